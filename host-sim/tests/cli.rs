//! The `slf` command end to end (assert_cmd): scene -> simulate -> decode -> eval, and bad
//! files and arguments giving one readable error line and a non-zero exit, never a panic.

use assert_cmd::Command;

fn slf() -> Command {
    Command::cargo_bin("slf").unwrap()
}

fn stdout(cmd: &mut Command) -> String {
    let out = cmd.assert().success().get_output().stdout.clone();
    String::from_utf8(out).unwrap()
}

fn failure(cmd: &mut Command) -> String {
    let out = cmd.assert().failure().get_output().clone();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!err.contains("panicked"), "panic: {err}");
    assert!(err.starts_with("error"), "not an error line: {err}");
    err
}

#[test]
fn scene_simulate_decode_eval_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "20", "-o"]).arg(p("truth.npy")));
    stdout(
        slf()
            .arg("simulate")
            .arg(p("truth.npy"))
            .arg("-o")
            .arg(p("cap"))
            .args(["--mask", "pixel", "-s", "3", "--format", "png"]),
    );
    assert!(p("cap/capture.json").exists() && p("cap/snapshot_2.png").exists());
    let out = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("recon.npy")).arg("--quiet"));
    assert!(out.contains("decoded 64 patches (0 flagged, 0 failed, 0 tiles failed)"), "{out}");
    let out = stdout(slf().arg("eval").arg(p("truth.npy")).arg(p("recon.npy")));
    let psnr: f64 = out.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(psnr > 30.0, "{out}");
    assert!(out.contains("data range") && out.contains("SSIM") && out.contains("SA"), "{out}");
    // The DCT on request, and the member map of the (default) ensemble decode.
    let out = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("dct.npy")).args(["--dictionary", "dct", "-q"]));
    assert!(out.contains("decoded 64 patches"), "{out}");
    stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("e.npy")).arg("--member-map").arg(p("map.csv")).arg("-q"));
    let map = std::fs::read_to_string(p("map.csv")).unwrap();
    assert_eq!(map.lines().next(), Some("lenslet_row,lenslet_col,view_row,view_col,member"));
    assert_eq!(map.lines().count(), 1 + 64);
    assert!(map.lines().skip(1).all(|l| l.rsplit(',').next().unwrap().parse::<u16>().unwrap() < 8));
    // A tiny training run writes a blob the decoder takes.
    let out = stdout(slf().arg("train").arg("-o").arg(p("e.slfd")).args([
        "--scenes",
        "2",
        "--size",
        "12",
        "--patches",
        "40",
        "--members",
        "3",
        "--iterations",
        "1",
        "--group",
        "8",
    ]));
    assert!(out.contains("coding error") && out.contains("vs DCT"), "{out}");
    stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("e2.npy")).arg("--blob").arg(p("e.slfd")).arg("-q"));
    std::fs::write(p("bad.slfd"), b"SLFDxx").unwrap();
    let e = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("e3.npy")).arg("--blob").arg(p("bad.slfd")));
    assert!(e.contains("dictionary blob"), "{e}");
    // A random training scene in uint16.
    stdout(slf().args(["scene", "random", "--seed", "4", "--size", "12", "--dtype", "u16", "-o"]).arg(p("r.npy")));
    // Every command has help.
    for c in ["demo", "scene", "simulate", "decode", "eval", "baseline", "sweep", "train", "compare"] {
        assert!(stdout(slf().args([c, "--help"])).contains("Usage"), "{c}");
    }
}

#[test]
fn bad_files_and_arguments_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let e = failure(slf().args(["scene", "nonsense", "-o"]).arg(p("x.npy")));
    assert!(e.contains("unknown scene \"nonsense\""), "{e}");
    let e = failure(slf().arg("decode").arg(p("missing")).arg("-o").arg(p("x.npy")));
    assert!(e.contains("capture.json"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    std::fs::write(p("junk.npy"), b"\x93NUMPY junk").unwrap();
    let e = failure(slf().arg("eval").arg(p("junk.npy")).arg(p("junk.npy")));
    assert!(e.contains("junk.npy"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    let e = failure(slf().arg("simulate").arg(p("junk.npy")).arg("-o").arg(p("cap")));
    assert!(e.contains("junk.npy"), "{e}");
    // Shapes that differ.
    stdout(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(p("a.npy")));
    stdout(slf().args(["scene", "smooth", "--size", "13", "-o"]).arg(p("b.npy")));
    let e = failure(slf().arg("eval").arg(p("a.npy")).arg(p("b.npy")));
    assert!(e.contains("shapes differ"), "{e}");
    // Out-of-range solver and mask arguments.
    stdout(slf().arg("simulate").arg(p("a.npy")).arg("-o").arg(p("cap")));
    let e = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--sigma-f", "1.5"]));
    assert!(e.contains("sigma_f"), "{e}");
    let e = failure(slf().arg("simulate").arg(p("a.npy")).arg("-o").arg(p("cap2")).args(["-s", "14"]));
    assert!(e.contains("14 snapshots"), "{e}");
    // clap's own errors: unknown flag, bad value, missing argument; one line each.
    for args in
        [&["decode", "--bogus"][..], &["simulate", "x.npy", "-o", "y", "--mask", "stripes"], &["eval", "a.npy"], &[]]
    {
        let e = failure(slf().args(args));
        assert_eq!(e.lines().count(), 1, "{args:?}: {e}");
    }
}

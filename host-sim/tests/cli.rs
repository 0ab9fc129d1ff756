//! The `slf` command end to end (assert_cmd): scene -> simulate -> decode -> eval, and bad
//! files and arguments giving one readable error line and a non-zero exit, never a panic.

use assert_cmd::Command;

mod common;

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

/// Whether the default decode of `cap` reports its grey-world gains.
fn out_default_has_gains(cap: &std::path::Path) -> bool {
    let dir = tempfile::tempdir().unwrap();
    let out = stdout(slf().arg("decode").arg(cap).arg("-o").arg(dir.path().join("x.npy")).arg("-q"));
    out.contains("white balance: grey world, gains ")
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
    let out = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("recon.npy")).args([
        "--quiet",
        "--disparities",
        "0:0",
    ]));
    // 20 x 20 lenslets, the full-view patch (one angular window): 4 x 4 disjoint blocks
    // and, at the default stride 2, the grids at offsets 0, 2 and 4 on each axis (4, 3 and
    // 3 whole patches a row) but (0, 0): (4 + 3 + 3)^2 - 16 = 84 (unsheared: a block
    // sheared at the frame's edge adds its unsheared fallback).
    assert!(out.contains("decoded 100 patches (100 solved, 0 interpolated from fewer than 5 bands, 0 flat; 0 flagged, 0 failed, 0 tiles failed)"), "{out}");
    // The capture's noise by default (2 DN read noise, 20,000 electrons at white); exact
    // or a given noise on request, not both.
    assert!(out.contains("projection: the capture's noise (sd 5.57e-4 + shot 5.00e-5 per unit)"), "{out}");
    let exact = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--exact", "-q"]));
    assert!(exact.contains("projection: exact projection"), "{exact}");
    let given = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--noise", "1e-3", "-q"]));
    assert!(given.contains("projection: noise sd 1.00e-3 + shot 0.00e0 per unit"), "{given}");
    let e = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--exact", "--noise", "1e-3"]));
    assert!(e.contains("--exact") && e.contains("--noise"), "{e}");
    let out = stdout(slf().arg("eval").arg(p("truth.npy")).arg(p("recon.npy")));
    let psnr: f64 = out.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(psnr > 30.0, "{out}");
    assert!(out.contains("data range") && out.contains("SSIM") && out.contains("SA"), "{out}");
    // A reader that closes the pipe before slf writes (`slf eval A B | head`) is no error.
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("slf"))
        .arg("eval")
        .arg(p("truth.npy"))
        .arg(p("recon.npy"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let done = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(done.status.success() && !err.contains("panicked"), "{:?}: {err}", done.status);
    // The white balance: grey world by default, off, or given gains (13 of them).
    assert!(out_default_has_gains(&p("cap")), "no white balance line");
    let off = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--balance", "off", "-q"]));
    assert!(off.contains("white balance: off"), "{off}");
    let ones = vec!["1"; 13].join(",");
    let given = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--gains", &ones, "-q"]));
    assert!(given.contains("white balance: given gains 1.000 1.000"), "{given}");
    failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--gains", "1,2,3"]));
    // The DCT on request, and the member map of the (default) ensemble decode.
    let out = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("dct.npy")).args([
        "--dictionary",
        "dct",
        "-q",
        "--disparities=0:0",
    ]));
    assert!(out.contains("decoded 100 patches"), "{out}");
    stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("e.npy")).arg("--member-map").arg(p("map.csv")).arg("-q"));
    let map = std::fs::read_to_string(p("map.csv")).unwrap();
    assert_eq!(map.lines().next(), Some("lenslet_row,lenslet_col,view_row,view_col,disparity,decoder,member"));
    // Every patch (with the default disparity search, the 100 of the grids and the unsheared
    // fallbacks of the blocks sheared at the frame's edge), the grid's each once.
    let grid: std::collections::HashSet<String> =
        map.lines().skip(1).map(|l| l.split(',').take(4).collect::<Vec<_>>().join(",")).collect();
    assert!(
        grid.len() == 100 && map.lines().count() > 100,
        "{} patches, {} origins",
        map.lines().count() - 1,
        grid.len()
    );
    // A member's row names it (the shipped ensemble's 8); any other decoder's names none.
    assert!(map.lines().skip(1).all(|l| {
        let f: Vec<&str> = l.split(',').collect();
        match f[5] {
            "member" => f[6].parse::<u16>().is_ok_and(|m| m < 8),
            _ => f[6].is_empty(),
        }
    }));
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
    // Its trained schedules, by one more command; the decode takes them, and the hand-set
    // schedule's flags are refused beside them.
    let out = stdout(slf().arg("train-schedule").arg(p("e.slfd")).arg("-o").arg(p("es.slfd")).args([
        "--scenes",
        "2",
        "--size",
        "12",
        "--patches",
        "8",
        "--iterations",
        "2",
        "--batch",
        "4",
        "--cold-steps",
        "4",
        "--warm-steps",
        "3",
        "--alone-steps",
        "3",
    ]));
    assert!(out.contains("| cold | 4 |") && out.contains("| warm | 3 |") && out.contains("| alone | 3 |"), "{out}");
    let es = std::fs::read(p("es.slfd")).unwrap();
    assert_eq!(u16::from_le_bytes([es[4], es[5]]), 2, "a blob with schedules is format version 2");
    let log = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("e4.npy")).arg("--blob").arg(p("es.slfd")));
    assert!(log.contains("4.0 steps a patch") || log.contains("3.0 steps a patch"), "{log}");
    let e = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("e5.npy")).args(["--sigma-f", "0.8"]));
    assert!(e.contains("--sigma-f sets the hand-set schedule") && e.contains("--schedule annealed"), "{e}");
    stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("e5.npy")).args([
        "--sigma-f",
        "0.8",
        "--schedule",
        "annealed",
        "-q",
    ]));
    let e = failure(slf().arg("train-schedule").arg(p("es.slfd")).arg("-o").arg(p("es.slfd")));
    assert!(e.lines().count() == 1, "{e}");
    std::fs::write(p("bad.slfd"), b"SLFDxx").unwrap();
    let e = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("e3.npy")).arg("--blob").arg(p("bad.slfd")));
    assert!(e.contains("dictionary blob"), "{e}");
    // A random training scene in uint16.
    stdout(slf().args(["scene", "random", "--seed", "4", "--size", "12", "--dtype", "u16", "-o"]).arg(p("r.npy")));
    // Every command has help.
    for c in ["demo", "scene", "simulate", "decode", "eval", "baseline", "sweep", "train", "train-schedule", "compare"]
    {
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
    // Each cause said once (issue 32, item 11): a missing file, a file that is no PNG.
    let e = failure(slf().arg("eval").arg(p("none.npy")).arg(p("none.npy")));
    assert_eq!(e.matches("(os error 2)").count(), 1, "{e}");
    std::fs::create_dir(p("views")).unwrap();
    std::fs::write(p("views").join("input_Cam020.png"), b"not a png").unwrap();
    let e = failure(slf().args(["import", "views"]).arg(p("views")).arg("-o").arg(p("v.npy")));
    assert!(e.contains("not an image slf reads"), "{e}");
    assert_eq!(e.matches("Invalid PNG signature").count(), 1, "{e}");
    // Shapes that differ.
    stdout(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(p("a.npy")));
    stdout(slf().args(["scene", "smooth", "--size", "13", "-o"]).arg(p("b.npy")));
    let e = failure(slf().arg("eval").arg(p("a.npy")).arg(p("b.npy")));
    assert!(e.contains("shapes differ"), "{e}");
    // Out-of-range solver and mask arguments.
    stdout(slf().arg("simulate").arg(p("a.npy")).arg("-o").arg(p("cap")));
    let e = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--sigma-f", "1.5"]));
    assert!(e.contains("--sigma-f 1.5: must be in (0, 1)"), "{e}");
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

fn stderr_of_success(cmd: &mut Command) -> String {
    let out = cmd.assert().success().get_output().stderr.clone();
    String::from_utf8(out).unwrap()
}

#[test]
fn out_of_range_arguments_name_the_argument_and_its_range() {
    let dir = tempfile::tempdir().unwrap();
    let x = dir.path().join("x.npy");
    // Before: panics (size 0), a 63 TB allocation (views 100000), an unusable file (views 0).
    let cases: &[(&[&str], &str)] = &[
        (&["scene", "depth", "--size", "0"], "'--size <SIZE>': 0 is out of range 11..=4096"),
        (&["scene", "depth", "--size", "4"], "'--size <SIZE>': 4 is out of range 11..=4096"),
        (&["scene", "depth", "--size", "100000000"], "100000000 is out of range 11..=4096"),
        (&["scene", "depth", "--views", "100000", "--size", "11"], "'--views <VIEWS>': 100000 is out of range 4..=16"),
        (&["scene", "depth", "--views", "0"], "'--views <VIEWS>': 0 is out of range 4..=16"),
        (&["scene", "depth", "--views", "3"], "'--views <VIEWS>': 3 is out of range 4..=16"),
        (&["scene", "depth", "--views", "16", "--size", "4096"], "--size 4096 with --views 16"),
        (
            &["scene", "depth", "--views", "16", "--size", "4096", "--rows", "2048"],
            "--size 4096 --rows 2048 with --views 16",
        ),
        (&["scene", "depth", "--rows", "10"], "'--rows <ROWS>': 10 is out of range 11..=4096"),
        (&["demo", "--size", "0"], "0 is out of range 11..=2048"),
        (&["compare", "--size", "0"], "0 is out of range 11..=1024"),
        (&["sweep", "--size", "3"], "3 is out of range 11..=1024"),
        (&["train", "--members", "0"], "'--members <MEMBERS>': 0 is out of range 1..=256"),
        (&["baseline", "--patches", "0"], "'--patches <PATCHES>': 0 is out of range 1..=1000"),
    ];
    for (args, want) in cases {
        let mut cmd = slf();
        cmd.current_dir(dir.path()).args(*args);
        if args[0] == "scene" {
            cmd.arg("-o").arg(&x);
        }
        let e = failure(&mut cmd);
        assert!(e.contains(want), "{args:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{args:?}: {e}");
    }
    assert!(!x.exists(), "no file written");
    let cap = dir.path().join("cap");
    stdout(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(&x));
    for (flag, value, want) in [
        ("--full-well", "0", "not a finite number above 0"),
        ("--full-well", "NaN", "not a finite number above 0"),
        ("--read-noise", "-1", "not a finite number at or above 0"),
        ("--defects", "1", "not a fraction in [0, 1)"),
        ("--defects", "-0.1", "not a fraction in [0, 1)"),
        ("--format", "tiff", "invalid value 'tiff' for '--format"),
    ] {
        let e = failure(slf().arg("simulate").arg(&x).arg("-o").arg(&cap).arg(format!("{flag}={value}")));
        assert!(e.contains(want) && e.contains(flag), "{flag} {value}: {e}");
    }
    assert!(!cap.exists());
}

#[test]
fn nothing_decoded_is_a_failure_and_many_flagged_patches_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(p("lf.npy")));
    // A light field far above white: simulate warns, and every patch is saturated.
    let lf = slf_host::io::lightfield::read_npy(&p("lf.npy")).unwrap();
    let bright = slf_host::io::lightfield::LightField { data: lf.data.iter().map(|_| 50.0).collect(), ..lf.clone() };
    slf_host::io::lightfield::write_npy(&p("bright.npy"), &bright, slf_host::io::lightfield::Dtype::F32).unwrap();
    let warn = stderr_of_success(slf().arg("simulate").arg(p("bright.npy")).arg("-o").arg(p("cap")));
    assert!(warn.contains("warning") && warn.contains("3600 of 3600 pixels (100.00 %) saturated"), "{warn}");
    // Before: exit 0 and a file of zeros.
    let e = failure(
        slf().arg("decode").arg(p("cap")).arg("-o").arg(p("out.npy")).arg("-q").arg("--member-map").arg(p("m.csv")),
    );
    // 12 x 12 lenslets, the full-view patch (one angular window): 3 x 3 disjoint blocks
    // (with the edge strip) and, at the default stride 2, the grids at offsets 0, 2 and 4
    // on each axis (2, 2 and 1 whole patches a row) but (0, 0): (2 + 2 + 1)^2 - 4 = 21.
    assert!(e.contains("no patch decoded (30 failed"), "{e}");
    assert!(!p("out.npy").exists() && !p("m.csv").exists(), "nothing written");
    // Half the pixels defective: every patch flagged, decoded, and a warning with the count.
    stdout(slf().arg("simulate").arg(p("lf.npy")).arg("-o").arg(p("cap2")).arg("--defects=0.5"));
    let out = slf()
        .arg("decode")
        .arg(p("cap2"))
        .arg("-o")
        .arg(p("out.npy"))
        .args(["-q", "--disparities", "0:0"])
        .assert()
        .success();
    let err = String::from_utf8(out.get_output().stderr.clone()).unwrap();
    assert!(err.contains("warning") && err.contains("30 were flagged"), "{err}");
    // No warning on a clean capture.
    stdout(slf().arg("simulate").arg(p("lf.npy")).arg("-o").arg(p("cap3")));
    let err = stderr_of_success(slf().arg("decode").arg(p("cap3")).arg("-o").arg(p("out3.npy")).arg("-q"));
    assert!(err.is_empty(), "{err}");
}

#[test]
fn bad_light_fields_are_refused_with_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(p("lf.npy")));
    let lf = slf_host::io::lightfield::read_npy(&p("lf.npy")).unwrap();
    // (H, W, U, V, B) read as (U, V, H, W, B): more views than lenslets.
    let mut swapped = slf_host::io::lightfield::LightField::zeros((12, 12), 5, 5, 13);
    for (u, v, y, x, b) in (0..5).flat_map(|u| {
        (0..5).flat_map(move |v| {
            (0..12).flat_map(move |y| (0..12).flat_map(move |x| (0..13).map(move |b| (u, v, y, x, b))))
        })
    }) {
        let i = swapped.index(y, x, u, v, b);
        swapped.data[i] = lf.get(u, v, y, x, b);
    }
    slf_host::io::lightfield::write_npy(&p("swapped.npy"), &swapped, slf_host::io::lightfield::Dtype::F32).unwrap();
    let e = failure(slf().arg("simulate").arg(p("swapped.npy")).arg("-o").arg(p("cap")));
    assert!(e.contains("swapped.npy") && e.contains("(H, W, U, V, B)"), "{e}");
    // NaN in a light field: eval, simulate and train refuse it (before: "PSNR NaN", exit 0;
    // train panicked).
    let mut nan = lf.clone();
    nan.data.iter_mut().for_each(|x| *x = f32::NAN);
    // (Written byte by byte: slf itself writes no light field holding NaN.)
    let header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {:?}, }}", lf.shape())
        .replace('[', "(")
        .replace(']', ")");
    let body: Vec<u8> = nan.data.iter().flat_map(|x| x.to_le_bytes()).collect();
    std::fs::write(p("nan.npy"), common::npy_bytes(1, &header, &body)).unwrap();
    assert!(slf_host::io::lightfield::write_npy(&p("nan2.npy"), &nan, slf_host::io::lightfield::Dtype::F32).is_err());
    for args in [
        vec!["eval", "lf.npy", "nan.npy"],
        vec!["eval", "nan.npy", "lf.npy"],
        vec!["simulate", "nan.npy", "-o", "c"],
        vec!["train", "-o", "t.slfd", "--input", "nan.npy"],
    ] {
        let e = failure(slf().current_dir(dir.path()).args(&args));
        assert!(e.contains("nan.npy") && e.contains("values are not finite"), "{args:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}

#[test]
fn every_argument_of_every_command_is_documented_in_its_help() {
    let commands = [
        "demo",
        "scene",
        "simulate",
        "decode",
        "eval",
        "baseline",
        "train",
        "sweep",
        "bench",
        "device-capture",
        "device-check",
        "compare",
    ];
    for c in commands {
        let help = stdout(slf().args([c, "--help"]));
        let lines: Vec<&str> = help.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let t = line.trim_start();
            // An option or argument line: `-o, --output <OUTPUT>  text` or `<TRUTH>  text`,
            // or (clap's long form) the spec alone with its text on the next, deeper line.
            let is_arg = (2..=6).contains(&(line.len() - t.len())) && (t.starts_with('-') || t.starts_with('<'));
            if !is_arg || t.starts_with("-h, --help") || t.starts_with("-V, --version") {
                continue;
            }
            let same_line = t.split_once("  ").map_or("", |(_, rest)| rest.trim());
            let indent = line.len() - t.len();
            let next = lines.get(i + 1).copied().unwrap_or("");
            let next_doc = if next.len() - next.trim_start().len() > indent { next.trim() } else { "" };
            let doc = if same_line.is_empty() { next_doc } else { same_line };
            assert!(
                !doc.is_empty() && !doc.starts_with('[') && !doc.starts_with("Possible values"),
                "slf {c}: undocumented argument: {line}"
            );
        }
    }
}

#[test]
fn sweep_files_name_their_basis_and_command() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("dct.md");
    stdout(slf().args(["sweep", "--size", "11", "--k", "1", "--dictionary", "dct", "-o"]).arg(&out));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("# Quality with the DCT"), "{text}");
    assert!(text.contains("sweep --size 11 --k 1 --dictionary dct"), "{text}");
    assert_eq!(
        text.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| scene") && !l.starts_with("| ---")).count(),
        15
    );
    stdout(slf().args(["sweep", "--size", "11", "--k", "1", "-o"]).arg(&out));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("# Quality with the ensemble screened"), "{text}");
    assert!(text.contains("--dictionary ensemble --choice screened"), "{text}");
}

#[test]
fn baselines_decode_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "15", "-o"]).arg(p("truth.npy")));
    stdout(slf().arg("simulate").arg(p("truth.npy")).arg("-o").arg(p("cap")));
    let mut psnr = Vec::new();
    for method in ["interpolate", "demosaic", "cs"] {
        let out = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("r.npy")).args(["--method", method, "-q"]));
        assert!(out.contains("wrote"), "{method}: {out}");
        let e = stdout(slf().arg("eval").arg(p("truth.npy")).arg(p("r.npy")));
        psnr.push(e.split_whitespace().nth(1).unwrap().parse::<f64>().unwrap());
    }
    assert!(psnr[0] < psnr[1], "interpolate {:.2} dB, demosaic {:.2} dB", psnr[0], psnr[1]);
    let e = failure(
        slf()
            .arg("decode")
            .arg(p("cap"))
            .arg("-o")
            .arg(p("x.npy"))
            .args(["--method", "demosaic", "--member-map"])
            .arg(p("m.csv")),
    );
    assert!(e.contains("--member-map needs --method cs"), "{e}");
    // Issue 41, item 9: a baseline refuses the compressed-sensing flags (before: ignored,
    // valid or not, exit 0) and a --disparity-map it would not write.
    let e = failure(
        slf()
            .arg("decode")
            .arg(p("cap"))
            .arg("-o")
            .arg(p("x.npy"))
            .args(["--method", "demosaic", "--disparity-map"])
            .arg(p("d.npy")),
    );
    assert!(e.contains("--disparity-map needs --method cs"), "{e}");
    for (method, flags, named) in [
        ("interpolate", vec!["--mu", "nan"], "--mu"),
        ("demosaic", vec!["--sigma-f", "5"], "--sigma-f"),
        ("ppid", vec!["--gains", "1,2"], "--gains"),
        ("demosaic", vec!["--blob", "/nonexistent"], "--blob"),
        ("ppid", vec!["--preset", "best", "--stride", "1"], "--preset, --stride"),
        // Issue 65, item 9: the trials' and the estimate's flags too (before: exit 0).
        ("demosaic", vec!["--shear-check"], "--shear-check"),
        ("ppid", vec!["--model-trial", "true"], "--model-trial"),
        ("interpolate", vec!["--shear-trial", "true"], "--shear-trial"),
        ("demosaic", vec!["--trial-by", "decode"], "--trial-by"),
        ("ppid", vec!["--baseline-blend", "true"], "--baseline-blend"),
        ("demosaic", vec!["--estimate-by", "patches"], "--estimate-by"),
    ] {
        let e = failure(
            slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args(["--method", method, "-q"]).args(&flags),
        );
        assert!(
            e.contains(&format!("{named} given with --method {method}, which uses none of the compressed-sensing"))
                && e.trim().lines().count() == 1,
            "{e}"
        );
    }
    assert!(!p("x.npy").exists() && !p("d.npy").exists());
}

#[test]
fn import_from_the_command_line_and_other_band_counts_resampled() {
    use slf_host::io::lightfield::{Dtype, LightField, read_npy, write_npy};
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    // A 31-band light field, 400..=700 nm by 10, flat 0.4: refused without its
    // wavelengths, resampled with them (flat stays 0.4 in all 13 bands).
    let mut lf = LightField::zeros((5, 5), 10, 10, 31);
    lf.data.iter_mut().for_each(|v| *v = 0.4);
    write_npy(&p("b31.npy"), &lf, Dtype::F32).unwrap();
    let e = failure(slf().arg("simulate").arg(p("b31.npy")).arg("-o").arg(p("cap")));
    assert!(e.contains("31 bands") && e.contains("--wavelengths"), "{e}");
    stdout(slf().arg("simulate").arg(p("b31.npy")).args(["--wavelengths", "400:700:10", "-o"]).arg(p("cap")));
    stdout(
        slf().args(["import", "bands"]).arg(p("b31.npy")).args(["--wavelengths", "400:700:10", "-o"]).arg(p("b13.npy")),
    );
    let b13 = read_npy(&p("b13.npy")).unwrap();
    assert_eq!(b13.shape(), [5, 5, 10, 10, 13]);
    assert!(b13.data.iter().all(|v| (v - 0.4).abs() < 1e-6));
    // A cube as .npy: needs wavelengths; then a 5 x 5 light field.
    let body: Vec<u8> = (0..6 * 7 * 4).flat_map(|_| 0.5f32.to_le_bytes()).collect();
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (6, 7, 4), }";
    std::fs::write(p("cube.npy"), common::npy_bytes(1, header, &body)).unwrap();
    let e = failure(slf().args(["import", "cube"]).arg(p("cube.npy")).arg("-o").arg(p("c.npy")));
    assert!(e.contains("4 bands") && e.contains("--wavelengths"), "{e}");
    stdout(
        slf()
            .args(["import", "cube"])
            .arg(p("cube.npy"))
            .args(["--wavelengths", "400,500,600,700", "-o"])
            .arg(p("c.npy")),
    );
    assert_eq!(read_npy(&p("c.npy")).unwrap().shape(), [5, 5, 6, 7, 13]);
    // A folder of views with none in the window is one error line naming a file.
    std::fs::create_dir(p("views")).unwrap();
    let e = failure(slf().args(["import", "views"]).arg(p("views")).arg("-o").arg(p("v.npy")));
    assert!(e.contains("input_Cam020.png"), "{e}");
    // Light fields the decoder could not take are refused by the import, with the minimum
    // (issue 32, item 12): not written for simulate or decode to refuse with a wrong hint.
    let e = failure(slf().args(["import", "views"]).arg(p("views")).args(["--views", "1,1", "-o"]).arg(p("v.npy")));
    assert!(e.contains("--views 1,1: the decoder needs at least 4,4"), "{e}");
    let e = failure(
        slf()
            .args(["import", "cube"])
            .arg(p("cube.npy"))
            .args(["--wavelengths", "400,500,600,700", "--resize", "3,3", "-o"])
            .arg(p("s.npy")),
    );
    assert!(e.contains("the import is 3 x 3 pixels a view: the decoder needs at least 5 x 5"), "{e}");
    // Issue 41, item 10: a --white that makes every value infinite is refused, not written.
    let e = failure(
        slf()
            .args(["import", "cube"])
            .arg(p("cube.npy"))
            .args(["--wavelengths", "400,500,600,700", "--white", "1e-40", "-o"])
            .arg(p("w.npy")),
    );
    assert!(e.contains("not finite") && e.contains("--white"), "{e}");
    assert!(!p("v.npy").exists() && !p("s.npy").exists() && !p("w.npy").exists());
}

#[test]
fn evaluate_compares_every_method_per_scene_and_on_average() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "15", "-o"]).arg(p("a.npy")));
    stdout(slf().args(["scene", "texture", "--size", "15", "-o"]).arg(p("b.npy")));
    stdout(slf().arg("evaluate").arg(p("a.npy")).arg(p("b.npy")).arg("-o").arg(p("out")));
    let table = std::fs::read_to_string(p("out/table.md")).unwrap();
    // 3 settings x (2 scenes + mean) x 8 methods (3 baselines, DCT and ensemble on disjoint
    // patches, the 3 presets), and a header of 2 lines.
    assert_eq!(table.lines().count(), 2 + 3 * 3 * 8, "{table}");
    for m in ["per-pixel interpolation", "neighbourhood demosaic", "PPID", "| DCT |", "| ensemble screened |"] {
        assert_eq!(table.matches(m).count(), 9, "{m}: {table}");
    }
    for m in ["| preset preview |", "| preset default |", "| preset best |"] {
        assert_eq!(table.matches(m).count(), 9, "{m}: {table}");
    }
    assert!(p("out/a_dct.png").exists() && p("out/b_baseline-ppid-mihoubi-et-al-2017.png").exists());
}

/// `--preset` names a basis, stride, window, disparities, edge fallback, sigma_min and
/// cold start: the preview decodes
/// the same bits as those flags spelled out (a dictionary named decodes without the model
/// trial unless asked), a flag given with a preset overrides the
/// preset's value, and `best` decodes more patches than the default.
#[test]
fn presets_are_their_flags_and_flags_override_them() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "depth", "--size", "15", "-o"]).arg(p("truth.npy")));
    stdout(slf().arg("simulate").arg(p("truth.npy")).arg("-o").arg(p("cap")).args(["--mask", "pixel"]));
    let decode = |out: &str, args: &[&str]| {
        let text = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p(out)).arg("-q").args(args));
        let patches = text.lines().find(|l| l.starts_with("decoded ")).unwrap().split(' ').nth(1).unwrap().to_string();
        (std::fs::read(p(out)).unwrap(), patches.parse::<usize>().unwrap())
    };
    let (preview, n_preview) = decode("preview.npy", &["--preset", "preview"]);
    let spelled = [
        "--dictionary",
        "dct",
        "--stride",
        "5",
        "--window",
        "uniform",
        "--disparities=-1:1",
        "--edge-fallback",
        "false",
        "--sheared-fallback",
        "true",
        "--sigma-min",
        "3e-3",
        "--model-trial",
        "true",
    ];
    let (flags, n_flags) = decode("flags.npy", &spelled);
    assert_eq!(n_preview, n_flags);
    assert!(preview == flags, "--preset preview is not its flags");
    // With the hand-set schedule the preview starts from the band-gain fill at 0.03.
    let (annealed, _) = decode("pa.npy", &["--preset", "preview", "--schedule", "annealed"]);
    let spelled_annealed = [&spelled[..], &["--schedule", "annealed", "--cold-start", "0.03"]].concat();
    let (flags_annealed, _) = decode("fa.npy", &spelled_annealed);
    assert!(annealed == flags_annealed, "--preset preview --schedule annealed is not its flags");
    assert!(annealed != preview, "the trained and the hand-set schedule decode the same");
    // A flag beside the preset wins: the preview at stride 3 decodes more patches, and
    // is the default's stride with the preview's other choices.
    let (_, n_stride3) = decode("s3.npy", &["--preset", "preview", "--stride", "3"]);
    assert!(n_stride3 > n_preview, "{n_stride3} <= {n_preview}");
    // The sheared fallback: off, the sheared blocks' unsheared patches are gone; the edge
    // fallback then adds those of the blocks at the frame's edge back.
    let (_, n_unfilled) = decode("uf.npy", &["--preset", "preview", "--sheared-fallback", "false"]);
    assert!(n_unfilled < n_preview, "{n_unfilled} >= {n_preview}");
    let (_, n_edges) =
        decode("fb.npy", &["--preset", "preview", "--sheared-fallback", "false", "--edge-fallback", "true"]);
    assert!(n_unfilled < n_edges && n_edges <= n_preview, "{n_unfilled} / {n_edges} / {n_preview}");
    let (default, n_default) = decode("default.npy", &[]);
    let (named, n_named) = decode("named.npy", &["--preset", "default"]);
    assert!(default == named && n_default == n_named, "--preset default is not the default");
    let (_, n_best) = decode("best.npy", &["--preset", "best"]);
    assert!(n_best > n_default && n_default > n_preview, "{n_best} / {n_default} / {n_preview}");
}

/// Where the results go is checked before the decode (issue 32, item 11): an output in a
/// missing folder or a folder as a file is refused first, and a file that exists is left
/// as it was when another output is refused.
#[test]
fn unwritable_outputs_are_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "11", "-o"]).arg(p("t.npy")));
    stdout(slf().arg("simulate").arg(p("t.npy")).arg("-o").arg(p("cap")));
    let e = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("missing/x.npy")));
    assert!(e.contains("cannot write") && e.contains("checked before the run"), "{e}");
    assert_eq!(e.matches("does not exist").count(), 1, "said once: {e}");
    let e = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("out.npy")).arg("--member-map").arg(dir.path()));
    assert!(e.contains("a folder"), "{e}");
    assert!(!p("out.npy").exists(), "no output left behind");
    std::fs::write(p("keep.npy"), b"old").unwrap();
    failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("keep.npy")).arg("--disparity-map").arg(p("no/d.npy")));
    assert_eq!(std::fs::read(p("keep.npy")).unwrap(), b"old");
}

/// `slf evaluate` names rows and previews by the file's stem: two inputs of one stem are
/// refused before anything is decoded (issue 32, item 6).
#[test]
fn evaluate_refuses_two_inputs_of_one_name() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    std::fs::create_dir_all(p("a")).unwrap();
    std::fs::create_dir_all(p("b")).unwrap();
    stdout(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(p("a/s.npy")));
    stdout(slf().args(["scene", "texture", "--size", "12", "-o"]).arg(p("b/s.npy")));
    let e = failure(slf().arg("evaluate").arg(p("a/s.npy")).arg(p("b/s.npy")).arg("-o").arg(p("out")));
    assert!(e.contains("both named \"s\"") && e.contains("rename one"), "{e}");
    assert!(!p("out/table.md").exists());
}

/// Sizes and indices from the import's flags are checked before anything is allocated or
/// read (issue 32, items 1-3): a resize to 4000 x 4000 (25 views x 16 M pixels x 13 bands,
/// 21 GB of f32) or 65536 x 65536, a wavelength step that would give 3e32 samples, an index
/// base that would wrap the view numbers; each one error line, no output, no abort.
#[test]
fn import_sizes_and_indices_are_checked_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    std::fs::create_dir(p("views")).unwrap();
    for r in 0..9 {
        for c in 0..9 {
            let img = image::RgbImage::from_pixel(8, 8, image::Rgb([100, 120, 140]));
            img.save(p("views").join(format!("input_Cam{:03}.png", r * 9 + c))).unwrap();
            img.save(p("views").join(format!("lf_{r:02}_{c:02}.png"))).unwrap();
        }
    }
    let e = failure(
        slf().args(["import", "views"]).arg(p("views")).args(["--resize", "4000,4000", "-o"]).arg(p("big.npy")),
    );
    assert!(e.contains("more than the 1073741824 (4 GiB) a light field may hold"), "{e}");
    let body: Vec<u8> = (0..6 * 7 * 31).flat_map(|_| 0.5f32.to_le_bytes()).collect();
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (6, 7, 31), }";
    std::fs::write(p("cube.npy"), common::npy_bytes(1, header, &body)).unwrap();
    let e = failure(
        slf()
            .args(["import", "cube"])
            .arg(p("cube.npy"))
            .args(["--wavelengths", "400:700:10", "--resize", "65536,65536", "-o"])
            .arg(p("big.npy")),
    );
    assert!(e.contains("4 GiB") && e.contains("65536 x 65536 pixels"), "{e}");
    let e = failure(
        slf()
            .args(["import", "cube"])
            .arg(p("cube.npy"))
            .args(["--wavelengths", "400:700:1e-30", "-o"])
            .arg(p("w.npy")),
    );
    assert!(e.contains("samples is more than 100000"), "{e}");
    let e = failure(
        slf()
            .args(["import", "views"])
            .arg(p("views"))
            .args(["--pattern", "lf_{row:02}_{col:02}.png", "--index-base", "18446744073709551615", "-o"])
            .arg(p("wrap.npy")),
    );
    assert!(e.contains("index base 18446744073709551615") && e.contains("past the largest index"), "{e}");
    for f in ["big.npy", "w.npy", "wrap.npy"] {
        assert!(!p(f).exists(), "{f} written");
    }
    // The same folder and cube within the limits import.
    stdout(slf().args(["import", "views"]).arg(p("views")).args(["--resize", "20,20", "-o"]).arg(p("ok.npy")));
    stdout(
        slf()
            .args(["import", "views"])
            .arg(p("views"))
            .args(["--pattern", "lf_{row:02}_{col:02}.png", "--index-base", "0", "-o"])
            .arg(p("ok2.npy")),
    );
}

/// Interpolated patches are counted apart from solved ones, in the summary and the member
/// map (issue 32, item 8): a kronecker capture at k = 3 interpolates the patches that see
/// fewer than 5 bands; the pixel mask solves every patch.
#[test]
fn interpolated_patches_are_counted_and_mapped_apart() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "15", "-o"]).arg(p("s.npy")));
    let count = |line: &str, what: &str| -> u32 {
        let i = line.find(what).unwrap_or_else(|| panic!("no {what:?} in {line}"));
        line[..i].trim_end().rsplit([' ', '(']).next().unwrap().parse().unwrap()
    };
    for (mask, k, interpolates) in [("kronecker", "3", true), ("pixel", "1", false)] {
        let cap = p(&format!("cap-{mask}"));
        stdout(slf().arg("simulate").arg(p("s.npy")).args(["--mask", mask, "-s", k, "-o"]).arg(&cap));
        let map = p(&format!("{mask}.csv"));
        let out = stdout(
            slf().arg("decode").arg(&cap).args(["--stride", "5", "-o"]).arg(p("x.npy")).arg("--member-map").arg(&map),
        );
        let line = out.lines().find(|l| l.starts_with("decoded ")).unwrap();
        let (decoded, solved, interpolated) =
            (count(line, " patches"), count(line, " solved"), count(line, " interpolated from fewer than 5 bands"));
        let csv = std::fs::read_to_string(&map).unwrap();
        let rows: Vec<&str> = csv.lines().skip(1).collect();
        let in_map = |d: &str| rows.iter().filter(|r| r.split(',').nth(5) == Some(d)).count() as u32;
        assert_eq!(rows.len() as u32, decoded, "{line}");
        assert_eq!(in_map("interpolated"), interpolated, "{line}");
        assert_eq!(in_map("member") + in_map("dictionary"), solved, "{line}");
        assert_eq!(decoded, solved + interpolated + in_map("flat"), "{line}");
        if interpolates {
            assert!(interpolated > 0 && interpolated < decoded, "{line}");
        } else {
            assert_eq!(interpolated, 0, "{line}");
        }
    }
}

/// On a kronecker mask the default blends with PPID (issue 63); a blend that cannot be made
/// (here: the memory cap, 0.01 GiB, below its two PPID light fields, about 12 MB at 44 x 44
/// lenslets) leaves the decode alone, said in
/// one line, exit 0, the same output as `--baseline-blend false`.
#[test]
fn a_blend_that_cannot_be_made_leaves_the_decode_alone() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "44", "-o"]).arg(p("s.npy")));
    stdout(slf().arg("simulate").arg(p("s.npy")).args(["--mask", "kronecker", "-s", "3", "-o"]).arg(p("cap")));
    let blended = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("b.npy")));
    assert!(blended.contains("baseline blend: PPID's weight"), "{blended}");
    let capped = stdout(slf().args(["--max-memory", "0.01", "decode"]).arg(p("cap")).arg("-o").arg(p("c.npy")));
    let line = capped.lines().find(|l| l.starts_with("baseline blend:")).unwrap_or_default();
    assert!(
        line.starts_with("baseline blend: not made (") && line.contains("cap") && line.ends_with("the decode alone"),
        "{capped}"
    );
    stdout(slf().arg("decode").arg(p("cap")).args(["--baseline-blend", "false", "-o"]).arg(p("d.npy")));
    assert_eq!(std::fs::read(p("c.npy")).unwrap(), std::fs::read(p("d.npy")).unwrap());
    assert_ne!(std::fs::read(p("b.npy")).unwrap(), std::fs::read(p("d.npy")).unwrap());
}

/// `slf bench --from CSV --device CSV` draws a sweep's table again with the device's frame
/// figure after it (seconds = solves x instructions / clock), without sweeping; a bad
/// device file is one error line naming its line, and nothing is written.
#[test]
fn bench_adds_the_devices_frame_figure_to_a_sweeps_table() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.csv");
    std::fs::write(
        &sweep,
        "mask,k,setting,psnr_db,ssim,sa_deg,ms_per_patch_1_thread,ms_per_patch_all_threads,solves_per_patch,frame_512_s_1_thread,pareto\n\
         pixel,1,preset default,29.9800,0.94060,4.4100,4.2600,2.1700,6.20,177.40,true\n\
         pixel,1,preset preview,24.4500,0.80860,7.9100,0.4800,0.2500,1.00,19.80,true\n",
    )
    .unwrap();
    let device = dir.path().join("device.csv");
    std::fs::write(
        &device,
        "decode,patch_solves,instructions_per_solve,clock_mhz\n\"default kind\",6080,93587147,480\npreview kind,1600,52521593,480\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    slf().arg("bench").arg("--from").arg(&sweep).arg("--device").arg(&device).arg("--out").arg(&out).assert().success();
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    assert!(
        md.contains("| pixel | 1 | preset default | 29.98 | 0.9406 | 4.41 | 4.26 | 2.17 | 6.2 | 177.4 | yes |"),
        "{md}"
    );
    assert!(md.contains("## The device's frame figure"), "{md}");
    assert!(md.contains("| default kind | 6080 | 93.6 M | 480 | 1185 |"), "{md}");
    assert!(md.contains("| preview kind | 1600 | 52.5 M | 480 | 175 |"), "{md}");
    assert!(out.join("bench.png").is_file());

    std::fs::write(&device, "decode,patch_solves,instructions_per_solve,clock_mhz\nx,6080,-1,480\n").unwrap();
    let bad = dir.path().join("bad");
    let err = failure(slf().arg("bench").arg("--from").arg(&sweep).arg("--device").arg(&device).arg("--out").arg(&bad));
    assert!(err.contains("line 2: instructions_per_solve is -1"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!bad.exists());
}

/// The patch is a decode setting (issue 40): `--patch-views 4` the paper's patch in four
/// angular windows, `5` the full-view patch in one; unset, the one that fits the capture's
/// lenslets (or a given blob's own); what does not fit is one line naming both.
#[test]
fn patch_views_are_a_decode_setting_that_fits_the_capture() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "depth", "--size", "11", "-o"]).arg(p("five.npy")));
    stdout(slf().args(["scene", "depth", "--size", "11", "--views", "4", "-o"]).arg(p("four.npy")));
    for lf in ["five", "four"] {
        stdout(slf().arg("simulate").arg(p(&format!("{lf}.npy"))).arg("-o").arg(p(&format!("cap-{lf}"))));
    }
    let decode = |cap: &str, out: &str, args: &[&str]| {
        let text = stdout(
            slf()
                .arg("decode")
                .arg(p(cap))
                .arg("-o")
                .arg(p(out))
                .args(["-q", "--stride", "5", "--member-map"])
                .arg(p(&format!("{out}.csv")))
                .args(args),
        );
        let patch = text.lines().find(|l| l.starts_with("patch: ")).unwrap_or_default().to_string();
        let csv = std::fs::read_to_string(p(&format!("{out}.csv"))).unwrap();
        // The angular windows' origins (view_row, view_col) the member map names.
        let mut windows: Vec<(String, String)> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                (f[2].to_string(), f[3].to_string())
            })
            .collect();
        windows.sort();
        windows.dedup();
        (std::fs::read(p(out)).unwrap(), patch, windows)
    };
    let w = |v: &[(&str, &str)]| -> Vec<(String, String)> {
        v.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect()
    };
    // 5 x 5 views: four windows of the paper's patch (origins 0 and 1 per axis), one of
    // the full-view patch; unset is the full-view patch, bit for bit.
    let (four, patch4, windows4) = decode("cap-five", "four.npy", &["--patch-views", "4"]);
    assert_eq!(patch4, "patch: 5 x 5 x 4 x 4 x 13 (--patch-views 4)");
    assert_eq!(windows4, w(&[("0", "0"), ("0", "1"), ("1", "0"), ("1", "1")]));
    let (five, patch5, windows5) = decode("cap-five", "five.npy", &["--patch-views", "5"]);
    assert_eq!(patch5, "patch: 5 x 5 x 5 x 5 x 13 (--patch-views 5)");
    assert_eq!(windows5, w(&[("0", "0")]));
    assert!(four != five, "the two patches decode alike");
    let (unset, patch, _) = decode("cap-five", "unset.npy", &[]);
    assert!(unset == five && patch == patch5, "unset is not the full-view patch: {patch}");
    // The DCT too, and a 4-view ensemble blob decodes with its own patch.
    let (_, patch, _) = decode("cap-five", "dct.npy", &["--dictionary", "dct", "--patch-views", "5"]);
    assert_eq!(patch, patch5);
    std::fs::write(p("four.slfd"), slf_host::firmware::DEFAULT_ENSEMBLE).unwrap();
    let blob = p("four.slfd").display().to_string();
    let (with_blob, patch, _) = decode("cap-five", "blob.npy", &["--blob", &blob]);
    assert!(with_blob == four && patch == patch4, "a 4-view blob's own patch: {patch}");
    let e = failure(slf().arg("decode").arg(p("cap-five")).arg("-o").arg(p("x.npy")).args([
        "--blob",
        &blob,
        "--patch-views",
        "5",
    ]));
    assert!(
        e.contains("the ensemble blob is for 5 x 5 x 4 x 4 x 13 patches, this decode's patch is 5 x 5 x 5 x 5 x 13")
            && e.trim().lines().count() == 1,
        "{e}"
    );
    // 4 x 4 views: the paper's patch fits (one window), the full-view patch does not.
    let (_, patch, windows) = decode("cap-four", "four4.npy", &[]);
    assert_eq!((patch.as_str(), windows), ("patch: 5 x 5 x 4 x 4 x 13 (--patch-views 4)", w(&[("0", "0")])));
    let e = failure(slf().arg("decode").arg(p("cap-four")).arg("-o").arg(p("x.npy")).args(["--patch-views", "5"]));
    assert!(
        e.contains("--patch-views 5: the capture's lenslets have 4 x 4 views") && e.contains("--patch-views 4"),
        "{e}"
    );
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    let e = failure(slf().arg("decode").arg(p("cap-five")).arg("-o").arg(p("x.npy")).args(["--patch-views", "6"]));
    assert!(e.contains("--patch-views") && e.contains("4 (the paper's 4 x 4-view patch) or 5"), "{e}");
}

/// Issue 41, item 6: an output may never be an input or another output of the same run;
/// each such run is refused before it writes anything, and the capture stays as it was.
#[test]
fn an_output_is_never_an_input_or_another_output() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(p("truth.npy")));
    stdout(slf().arg("simulate").arg(p("truth.npy")).arg("-o").arg(p("cap")).args(["--format", "npy"]));
    let before: Vec<Vec<u8>> =
        ["capture.json", "snapshot_0.npy"].iter().map(|f| std::fs::read(p("cap").join(f)).unwrap()).collect();
    let decode = |out: std::path::PathBuf, extra: &[&str]| {
        failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(out).args(extra).arg("-q"))
    };
    for (out, extra, says) in [
        (p("cap/capture.json"), vec![], "may not be a file the run reads"),
        (p("cap/snapshot_0.npy"), vec![], "may not be a file the run reads"),
        // Another spelling of the same file.
        (p("cap/../cap/./snapshot_0.npy"), vec![], "may not be a file the run reads"),
        (p("x.npy"), vec!["--member-map", p("x.npy").to_str().unwrap()], "are the same file"),
        (p("x.npy"), vec!["--disparity-map", p("cap/capture.json").to_str().unwrap()], "may not be a file"),
    ] {
        let e = decode(out, &extra);
        assert!(e.contains(says) && e.trim().lines().count() == 1, "{e}");
    }
    let after: Vec<Vec<u8>> =
        ["capture.json", "snapshot_0.npy"].iter().map(|f| std::fs::read(p("cap").join(f)).unwrap()).collect();
    assert!(before == after, "the capture changed");
    assert!(!p("x.npy").exists());
    // A simulation whose capture would hold its own input; an import over its input.
    std::fs::copy(p("truth.npy"), p("cap/snapshot_0.npy")).unwrap();
    let e =
        failure(slf().arg("simulate").arg(p("cap/snapshot_0.npy")).arg("-o").arg(p("cap")).args(["--format", "npy"]));
    assert!(e.contains("may not be a file the run reads"), "{e}");
    let e = failure(
        slf()
            .args(["import", "bands"])
            .arg(p("truth.npy"))
            .arg("-o")
            .arg(p("truth.npy"))
            .args(["--wavelengths", "400:700"]),
    );
    assert!(e.contains("may not be a file the run reads"), "{e}");
}

/// Issue 41, item 7: a write that fails part way (here the file-size limit) leaves the
/// previous file whole, not a truncated one.
#[cfg(unix)]
#[test]
fn a_write_that_fails_leaves_the_previous_file_whole() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scene.npy");
    stdout(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(&out));
    let before = std::fs::read(&out).unwrap();
    // The same scene larger: 5 x 5 x 30 x 30 x 13 f32 is 1.2 MB, past a 64 KiB limit.
    let bin = assert_cmd::cargo::cargo_bin("slf");
    let status = std::process::Command::new("bash")
        .arg("-c")
        .arg(format!("ulimit -f 64; exec '{}' scene smooth --size 30 -o '{}'", bin.display(), out.display()))
        .status()
        .unwrap();
    assert!(!status.success(), "the write past the limit should fail");
    assert!(std::fs::read(&out).unwrap() == before, "the previous file is not whole");
}

/// Issue 41, item 16: what a later command would refuse is refused by the first one (a
/// scene eval cannot score, a capture decode cannot take), and values below 0 are said.
#[test]
fn the_first_command_refuses_what_a_later_one_would() {
    use slf_host::io::lightfield::{Dtype, LightField, read_npy, write_npy};
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let e = failure(slf().args(["scene", "smooth", "--size", "10", "-o"]).arg(p("s.npy")));
    assert!(e.contains("--size") && e.contains("11"), "{e}");
    // 3 x 3 views and 4 x 4 lenslets: no capture.
    for (views, size, says) in [(3, 12, "3 x 3 views"), (5, 4, "4 x 4 lenslets")] {
        let lf = LightField::zeros((views, views), size, size, 13);
        write_npy(&p("small.npy"), &lf, Dtype::F32).unwrap();
        let e = failure(slf().arg("simulate").arg(p("small.npy")).arg("-o").arg(p("cap")));
        assert!(e.contains(says) && e.contains("the decoder needs"), "{e}");
        assert!(!p("cap").exists());
    }
    // evaluate names the file and the command that mends it (issue 41, item 15).
    write_npy(&p("two.npy"), &LightField::zeros((5, 5), 12, 12, 2), Dtype::F32).unwrap();
    let e = failure(slf().arg("evaluate").arg(p("two.npy")).arg("-o").arg(p("ev")));
    assert!(e.contains("two.npy: 2 bands") && e.contains("slf import bands") && !e.contains("--wavelengths to"), "{e}");
    write_npy(&p("three.npy"), &LightField::zeros((3, 3), 12, 12, 13), Dtype::F32).unwrap();
    let e = failure(slf().arg("evaluate").arg(p("three.npy")).arg("-o").arg(p("ev")));
    assert!(e.contains("three.npy: 3 x 3 views") && !e.contains("the capture"), "{e}");
    // Negative radiance is recorded as no light, with a warning.
    let mut lf = LightField::zeros((5, 5), 12, 12, 13);
    lf.data.iter_mut().enumerate().for_each(|(i, x)| *x = if i % 7 == 0 { -0.5 } else { 0.3 });
    write_npy(&p("neg.npy"), &lf, Dtype::F32).unwrap();
    let out = slf().arg("simulate").arg(p("neg.npy")).arg("-o").arg(p("cap")).assert().success().get_output().clone();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("values below 0 (down to -0.500) recorded as no light"), "{err}");
    // A cube with negative reflectance: set to 0, with a note.
    let body: Vec<u8> = (0..6 * 7 * 4).flat_map(|i| if i == 5 { -0.87f32 } else { 0.5 }.to_le_bytes()).collect();
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (6, 7, 4), }";
    std::fs::write(p("cube.npy"), common::npy_bytes(1, header, &body)).unwrap();
    let out = slf()
        .args(["import", "cube"])
        .arg(p("cube.npy"))
        .args(["--wavelengths", "400,500,600,700", "-o"])
        .arg(p("c.npy"))
        .assert()
        .success()
        .get_output()
        .clone();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("below 0") && err.contains("set to 0"), "{err}");
    assert!(read_npy(&p("c.npy")).unwrap().data.iter().all(|&x| x >= 0.0));
}

/// Issue 43: a real sensor's scene and calibration captures from `slf simulate`, its
/// calibration from `slf calibrate` (a folder of captures, or the captures named); what
/// is not a calibration capture, one line and a failure.
#[test]
fn simulate_calibration_captures_then_calibrate() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "office", "--size", "12", "-o"]).arg(p("lf.npy")));
    let out = stdout(
        slf()
            .arg("simulate")
            .arg(p("lf.npy"))
            .arg("-o")
            .arg(p("scene"))
            .args(["--leakage", "0.1", "--vignetting", "0.4", "--dark-sd", "2", "--exposures", "2"])
            .arg("--calibration-captures")
            .arg(p("cal")),
    );
    assert!(out.contains("wrote 30 calibration captures"), "{out}");
    let out = stdout(slf().arg("calibrate").arg(p("cal")).arg("-o").arg(p("calibration")));
    assert!(out.contains("wrote"), "{out}");
    let c = slf_host::io::calibration::Calibration::load(&p("calibration")).unwrap();
    assert_eq!(c.description.sources.band, 26);
    assert!((c.description.response[6][6] - 0.9).abs() < 0.01, "{:?}", c.description.response[6]);
    // The captures named one by one: the same calibration.
    let names: Vec<_> = std::fs::read_dir(p("cal")).unwrap().map(|e| e.unwrap().path()).collect();
    stdout(slf().arg("calibrate").args(&names).arg("-o").arg(p("again")));
    assert_eq!(slf_host::io::calibration::Calibration::load(&p("again")).unwrap(), c);
    // A scene is no calibration capture; an empty folder holds none; --exposures alone asks
    // for the folder.
    let e = failure(slf().arg("calibrate").arg(p("scene")).arg(p("cal")).arg("-o").arg(p("x")));
    assert!(e.contains("a scene's capture") && e.lines().count() == 1, "{e}");
    std::fs::create_dir(p("empty")).unwrap();
    let e = failure(slf().arg("calibrate").arg(p("empty")).arg("-o").arg(p("x")));
    assert!(e.contains("holds no capture folder"), "{e}");
    let e = failure(slf().arg("simulate").arg(p("lf.npy")).arg("-o").arg(p("y")).args(["--exposures", "2"]));
    assert!(e.contains("--calibration-captures"), "{e}");
}

/// `--error-map` writes a lenslet map in the output's units without changing the decode,
/// `slf eval --error-map` compares it with the truth, `--plausible` takes its range.
#[test]
fn the_error_map_and_the_plausibility_check_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "texture", "--size", "20", "-o"]).arg(p("truth.npy")));
    stdout(slf().arg("simulate").arg(p("truth.npy")).arg("-o").arg(p("cap")).args(["-s", "3"]));
    let plain = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("plain.npy")).arg("-q"));
    assert!(
        plain.contains("plausibility: ") && plain.contains("+ 0.05)") && !plain.contains("error estimate"),
        "{plain}"
    );
    let out = stdout(
        slf().arg("decode").arg(p("cap")).arg("-o").arg(p("r.npy")).arg("-q").arg("--error-map").arg(p("e.npy")),
    );
    assert!(out.contains("error estimate: ") && out.contains("estimated PSNR "), "{out}");
    assert_eq!(std::fs::read(p("r.npy")).unwrap(), std::fs::read(p("plain.npy")).unwrap(), "the same decode");
    let map = slf_host::io::lightfield::read_npy_f32_2d(&p("e.npy"), (20, 20)).unwrap();
    assert!(map.iter().all(|e| e.is_finite() && *e > 0.0 && *e < 0.5), "{map:?}");
    let eval = stdout(slf().arg("eval").arg(p("truth.npy")).arg(p("r.npy")).arg("--error-map").arg(p("e.npy")));
    assert!(
        eval.contains("estimate PSNR ") && eval.contains("rank correlation") && eval.contains("(16 blocks)"),
        "{eval}"
    );
    assert!(eval.contains("over 0 of 16 blocks of 5 x 5 lenslets"), "{eval}");
    // A map of another frame is refused in one line.
    stdout(slf().args(["scene", "smooth", "--size", "25", "-o"]).arg(p("big.npy")));
    let err = failure(slf().arg("eval").arg(p("big.npy")).arg(p("big.npy")).arg("--error-map").arg(p("e.npy")));
    assert!(err.contains("want a map of 25 x 25 lenslets") && err.lines().count() == 1, "{err}");
    // The check's flag: off, or in range.
    let off = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("o.npy")).args(["-q", "--plausible", "off"]));
    assert!(off.contains("plausibility: off"), "{off}");
    for bad in ["0.5:0.05", "2:-1", "2", "x:y", "nan:0.1"] {
        let err = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("o.npy")).args(["--plausible", bad]));
        assert!(err.contains("want FACTOR:MARGIN") && err.lines().count() == 1, "{bad}: {err}");
    }
    let err = failure(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("o.npy")).args([
        "--method",
        "demosaic",
        "--estimate",
    ]));
    assert!(err.contains("need --method cs"), "{err}");
}

/// Issue 49's blow-up: dark shade and water beside a bright canopy, decoded by the DCT alone
/// (the alone schedule from the band-gain fill) with the plausibility check off: no block of
/// 5 x 5 lenslets above twice its truth + 0.05 (13 of 64 were, at the output's clamp, while a
/// dark pixel's fill gain was its noise over its bands' noise).
#[test]
fn a_dark_canopy_decodes_without_a_blow_up_even_unchecked() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "canopy-dim", "--size", "40", "-o"]).arg(p("truth.npy")));
    stdout(slf().arg("simulate").arg(p("truth.npy")).arg("-o").arg(p("cap")).args(["--seed", "1"]));
    for flags in [&["--dictionary", "dct", "--plausible", "off"][..], &["--preset", "preview", "--plausible", "off"]] {
        stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("r.npy")).arg("-q").args(flags));
        let eval = stdout(slf().arg("eval").arg(p("truth.npy")).arg(p("r.npy")));
        assert!(eval.contains("over 0 of 64 blocks"), "{flags:?}: {eval}");
        let psnr: f64 = eval.split_whitespace().nth(1).unwrap().parse().unwrap();
        assert!(psnr > 20.0, "{flags:?}: {eval}");
    }
}

/// Issue 49, item 4: fine print at 0.7 pixels per view, whose half-pixel shears alias. The
/// shear check (the held-out estimate of a half-pixel block against its whole neighbours)
/// moves most blocks to whole shears and decodes far better, and so does the shear trial
/// (the default: the frame's pilots together), which says so; without either
/// (`--shear-trial false`), the decode is the one of before.
#[test]
fn the_shear_check_and_trial_take_whole_shears_where_half_ones_alias() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "print", "--size", "40", "-o"]).arg(p("truth.npy")));
    stdout(slf().arg("simulate").arg(p("truth.npy")).arg("-o").arg(p("cap")).args(["--seed", "2"]));
    let mut psnr = Vec::new();
    for flags in [&["--shear-trial", "false"][..], &["--shear-trial", "false", "--shear-check"], &[]] {
        let out = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("r.npy")).arg("-q").args(flags));
        assert_eq!(out.contains("shear trial: whole disparities only: the half ones alias"), flags.is_empty(), "{out}");
        let halves: usize = out
            .lines()
            .find_map(|l| l.strip_prefix("disparity: blocks per disparity "))
            .unwrap()
            .split(';')
            .next()
            .unwrap()
            .split(", ")
            .filter(|c| c.contains(".5:"))
            .map(|c| c.rsplit(' ').next().unwrap().parse::<usize>().unwrap())
            .sum();
        let eval = stdout(slf().arg("eval").arg(p("truth.npy")).arg(p("r.npy")));
        psnr.push((eval.split_whitespace().nth(1).unwrap().parse::<f64>().unwrap(), halves));
    }
    let ((plain, plain_halves), (checked, checked_halves), (trial, trial_halves)) = (psnr[0], psnr[1], psnr[2]);
    assert!(checked_halves * 2 < plain_halves, "{plain_halves} -> {checked_halves} half-pixel blocks");
    assert!(checked > plain + 5.0, "{plain:.2} -> {checked:.2} dB");
    assert_eq!(trial_halves, 0, "the trial's decode has whole disparities only");
    assert!(trial > plain + 5.0, "{plain:.2} -> {trial:.2} dB");
}

/// Issue 49, item 2: the model trial. The default decodes the frame with the model whose
/// held-out error over the pilots it prints is the smaller, and that decode is the model's
/// own without the trial, bit for bit; `--model-trial false` is the screened ensemble.
/// The summary's `model trial:` line of a decode: the line after its prefix, the model
/// it names as `--dictionary` spells it, and the printed held-out errors (DCT, ensemble).
fn model_trial_line(out: &str) -> (String, &'static str, f64, f64) {
    let line = out.lines().find_map(|l| l.strip_prefix("model trial: decoded by the ")).unwrap().to_string();
    let number = |after: &str| -> f64 {
        let rest = &line[line.find(after).unwrap() + after.len()..];
        rest.split([',', ')', ';']).next().unwrap().trim().parse().unwrap()
    };
    let (dct, ensemble) = (number("patches: DCT "), number(", ensemble "));
    let picked = if line.starts_with("DCT") { "dct" } else { "ensemble" };
    (line, picked, dct, ensemble)
}

#[test]
fn the_previews_model_trial_leans_to_the_dct_and_moves_only_where_the_ensemble_is_clearly_better() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let mut picks = Vec::new();
    for scene in ["speculars", "saturated"] {
        let truth = p(&format!("{scene}.npy"));
        stdout(slf().args(["scene", scene, "--size", "30", "-o"]).arg(&truth));
        let cap = p(&format!("cap-{scene}"));
        stdout(
            slf().arg("simulate").arg(&truth).arg("-o").arg(&cap).args(["--mask", "lenslet", "-s", "3", "--seed", "1"]),
        );
        let decode = |name: &str, flags: &[&str]| {
            let out = stdout(
                slf().arg("decode").arg(&cap).arg("-o").arg(p(name)).args(["-q", "--preset", "preview"]).args(flags),
            );
            (out, std::fs::read(p(name)).unwrap())
        };
        let (out, trial) = decode("trial.npy", &[]);
        let (line, picked, dct, ensemble) = model_trial_line(&out);
        // The lean: the ensemble only below 0.8 x the DCT's error (printed to 5 decimals).
        assert!((ensemble - 0.8 * dct).abs() > 1e-4, "too near the margin to check: {line}");
        assert_eq!(picked == "ensemble", ensemble < 0.8 * dct, "{scene}: {line}");
        let (_, alone) = decode("alone.npy", &["--model-trial", "false", "--dictionary", picked]);
        assert_eq!(trial, alone, "{scene}: {line}");
        // Without the trial the preview is the DCT's, as before it.
        let (off, by_dct) = decode("off.npy", &["--model-trial", "false"]);
        assert!(!off.contains("model trial"), "{off}");
        let (_, named) = decode("named.npy", &["--model-trial", "false", "--dictionary", "dct"]);
        assert_eq!(by_dct, named);
        if picked == "ensemble" {
            // Where the pilots favour the ensemble that clearly, it decodes nearer the truth.
            let psnr = |name: &str| -> f64 {
                let out = stdout(slf().arg("eval").arg(&truth).arg(p(name)));
                out.lines().find_map(|l| l.strip_prefix("PSNR ")).unwrap().split(' ').next().unwrap().parse().unwrap()
            };
            assert!(psnr("trial.npy") > psnr("off.npy"), "{scene}: {line}");
        }
        picks.push(picked);
    }
    // Both branches ran: the specular scene's pilots favour the ensemble by 2 x, the
    // saturated one's are within 10 %.
    assert_eq!(picks, ["ensemble", "dct"]);
}

/// The default's model trial: the model whose pilots err less, unless the two sums are
/// within their spread, where the line says so and the mask's favoured model decodes (the
/// ensemble at pixel k = 1, the DCT at pixel k = 3; no prior on the kronecker mask, where
/// no line says "within"). The frame is the picked model's own decode, bit for bit.
#[test]
fn the_model_trial_decodes_with_the_model_its_pilots_favour_or_on_a_tie_the_masks() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let mut ties = Vec::new();
    for scene in ["texture", "smooth"] {
        let truth = p(&format!("{scene}.npy"));
        stdout(slf().args(["scene", scene, "--size", "30", "-o"]).arg(&truth));
        for (mask, k, seed, prior) in
            [("pixel", "1", "1", Some("ensemble")), ("pixel", "3", "2", Some("dct")), ("kronecker", "3", "1", None)]
        {
            let cap = p(&format!("cap-{scene}-{mask}{k}"));
            stdout(
                slf().arg("simulate").arg(&truth).arg("-o").arg(&cap).args(["--mask", mask, "-s", k, "--seed", seed]),
            );
            let out = stdout(slf().arg("decode").arg(&cap).arg("-o").arg(p("trial.npy")).args([
                "-q",
                "--baseline-blend",
                "false",
            ]));
            let (line, picked, dct, ensemble) = model_trial_line(&out);
            let tied = line.contains("within their spread");
            match (tied, prior) {
                (true, Some(prior)) => assert_eq!(picked, prior, "{scene} {mask} k {k}: {line}"),
                (true, None) => panic!("{scene} {mask} k {k}: a tie without a prior: {line}"),
                (false, _) => assert_eq!(picked == "dct", dct < ensemble, "{scene} {mask} k {k}: {line}"),
            }
            ties.push(tied);
            stdout(slf().arg("decode").arg(&cap).arg("-o").arg(p("alone.npy")).args([
                "-q",
                "--baseline-blend",
                "false",
                "--model-trial",
                "false",
                "--dictionary",
                picked,
            ]));
            assert_eq!(
                std::fs::read(p("trial.npy")).unwrap(),
                std::fs::read(p("alone.npy")).unwrap(),
                "{scene} {mask} k {k}: {line}"
            );
            let off = stdout(
                slf().arg("decode").arg(&cap).arg("-o").arg(p("off.npy")).arg("-q").args(["--model-trial", "false"]),
            );
            assert!(!off.contains("model trial"), "{off}");
        }
    }
    // Both rules ran: some frames tied, some did not.
    assert!(ties.contains(&true) && ties.contains(&false), "{ties:?}");
}

/// `slf eval --border N` scores the lenslets `N` in from every edge: a reconstruction off by
/// 0.5 on its edge lenslets and by 0.01 inside scores the PSNR of 0.01 over the interior's
/// own maximum (computed here), an error map is cut the same way, and a border that leaves
/// nothing is one line naming the sizes.
#[test]
fn eval_scores_the_interior_with_a_border() {
    use slf_host::io::lightfield::{Dtype, LightField, write_npy, write_npy_f32_2d};
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let (rows, cols, border) = (16, 18, 2);
    let value = |s: usize, t: usize, b: usize| 0.1 + 0.002 * (s * cols + t) as f32 + 0.01 * b as f32;
    let truth = LightField::from_fn((3, 3), rows, cols, 13, |_, _, s, t, b| value(s, t, b));
    let edge = |s: usize, t: usize| s < border || t < border || s >= rows - border || t >= cols - border;
    let recon = LightField::from_fn((3, 3), rows, cols, 13, |_, _, s, t, b| {
        value(s, t, b) + if edge(s, t) { 0.5 } else { 0.01 }
    });
    write_npy(&p("truth.npy"), &truth, Dtype::F32).unwrap();
    write_npy(&p("recon.npy"), &recon, Dtype::F32).unwrap();
    let psnr = |out: &str| -> f64 {
        let line = out.lines().find(|l| l.starts_with("PSNR")).unwrap();
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    let inner_max = f64::from(value(rows - border - 1, cols - border - 1, 12));
    let want = 10.0 * (inner_max * inner_max / (0.01f64 * 0.01)).log10();
    let out = stdout(slf().arg("eval").arg(p("truth.npy")).arg(p("recon.npy")).args(["--border", "2"]));
    assert!((psnr(&out) - want).abs() < 0.01, "{out}: want {want:.3}");
    assert!(out.contains("scored: lenslets 2..14 x 2..16 of 16 x 18 (--border 2)"), "{out}");
    // The whole frame is scored without it, edges and all: far lower.
    let whole = stdout(slf().arg("eval").arg(p("truth.npy")).arg(p("recon.npy")));
    assert!(psnr(&whole) < want - 20.0, "{whole}");
    // An error map of the frame's lenslets is cut to the interior too.
    write_npy_f32_2d(&p("map.npy"), &vec![0.01; rows * cols], rows, cols).unwrap();
    let out = stdout(
        slf()
            .arg("eval")
            .arg(p("truth.npy"))
            .arg(p("recon.npy"))
            .args(["--border", "2", "--error-map"])
            .arg(p("map.npy")),
    );
    assert!(out.contains("estimate PSNR"), "{out}");
    let e = failure(slf().arg("eval").arg(p("truth.npy")).arg(p("recon.npy")).args(["--border", "8"]));
    assert!(e.contains("--border 8") && e.contains("16 x 18"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
}

/// Behind a turned lenslet grid the summary names the grid it decoded through, counts the
/// lenslets whose views fall past the sensor, and says when half-pixel shears (asked for)
/// read views at their cells' centres; the aligned sensor's summary has no such line.
#[test]
fn the_decode_names_its_lenslet_grid() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    stdout(slf().args(["scene", "smooth", "--size", "30", "-o"]).arg(p("lf.npy")));
    let sim = |out: &str, extra: &[&str]| {
        stdout(
            slf().arg("simulate").arg(p("lf.npy")).arg("-o").arg(p(out)).args(["-s", "1", "--seed", "2"]).args(extra),
        )
    };
    sim("cap", &["--rotation", "1", "--pitch", "5.1"]);
    let out = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).arg("-q").args([
        "--coverage-map",
        &p("cov.npy").display().to_string(),
        "--error-map",
        &p("em.npy").display().to_string(),
    ]));
    let line = out.lines().find(|l| l.starts_with("lenslet grid:")).unwrap_or_else(|| panic!("{out}"));
    assert!(line.starts_with("lenslet grid: turned 1.0000 degrees, pitch 5.1000 x 5.1000 px"), "{line}");
    assert!(line.contains("lenslets reach past the sensor's edges") && !line.contains("half-pixel"), "{line}");
    // Issue 66, item 4: the lenslets past the sensor in the coverage map, and left out of
    // the estimated PSNR, which is the map's over the rest.
    let number = |text: &str, after: &str| -> f64 {
        let rest = &text[text.find(after).unwrap_or_else(|| panic!("{after:?} in {text}")) + after.len()..];
        rest.split(|c: char| !(c.is_ascii_digit() || c == '.')).next().unwrap().parse().unwrap()
    };
    let past = number(line, "; ") as usize;
    let coverage = slf_host::io::lightfield::read_npy_f32_2d(&p("cov.npy"), (30, 30)).unwrap();
    assert_eq!(coverage.iter().filter(|&&c| c < 1.0).count(), past, "{line}");
    assert!(coverage.iter().all(|&c| (0.0..=1.0).contains(&c) && (c * 25.0).fract() == 0.0), "not shares of 25 views");
    let estimate = out.lines().find(|l| l.starts_with("error estimate:")).unwrap_or_else(|| panic!("{out}"));
    assert!(estimate.contains(&format!("the {past} lenslets that reach past the sensor left out")), "{estimate}");
    let errors = slf_host::io::lightfield::read_npy_f32_2d(&p("em.npy"), (30, 30)).unwrap();
    let kept: Vec<f64> =
        errors.iter().zip(&coverage).filter(|(e, c)| **c == 1.0 && e.is_finite()).map(|(e, _)| f64::from(*e)).collect();
    let range = number(estimate, "data range ");
    let want = 10.0 * (range * range / (kept.iter().map(|e| e * e).sum::<f64>() / kept.len() as f64)).log10();
    let got = number(estimate, "estimated PSNR ");
    assert!((got - want).abs() < 0.01, "estimated PSNR {got} dB, {want} over the lenslets on the sensor");
    let e = failure(
        slf()
            .arg("decode")
            .arg(p("cap"))
            .args(["--method", "demosaic", "--grid", "aligned", "-o"])
            .arg(p("y.npy"))
            .arg("--coverage-map")
            .arg(p("c2.npy")),
    );
    assert!(e.contains("--coverage-map needs --method cs"), "{e}");
    let out = stdout(slf().arg("decode").arg(p("cap")).arg("-o").arg(p("x.npy")).args([
        "-q",
        "--disparities",
        "-1:1:0.5",
        "--shear-trial",
        "false",
    ]));
    // Half-pixel patches read the grid by the cells' shares too (a half view's cell the mean
    // of two grid positions): no cell-centre read is reported.
    assert!(out.contains("each pixel the shares of the view cells it covers"), "{out}");
    assert!(!out.contains("under its cell's centre"), "{out}");
    sim("aligned", &[]);
    let out = stdout(slf().arg("decode").arg(p("aligned")).arg("-o").arg(p("x.npy")).arg("-q"));
    assert!(!out.contains("lenslet grid"), "{out}");
}

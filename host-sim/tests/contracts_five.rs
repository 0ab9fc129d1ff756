//! Issue 65 ("nothing lost, nothing silently wrong, round 5"): each defect an outside sweep
//! or an outside read found, through the `slf` command as a user meets it. Each test fails
//! on the code before its fix (the item's number is the issue's).

use std::path::{Path, PathBuf};
use std::process::Command as Std;

use assert_cmd::Command;

mod common;

fn slf() -> Command {
    Command::cargo_bin("slf").unwrap()
}

fn bin() -> PathBuf {
    assert_cmd::cargo::cargo_bin("slf")
}

/// Runs `cmd`, expects one error line and no panic, returns it.
fn failure(cmd: &mut Command) -> String {
    let out = cmd.assert().failure().get_output().clone();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!err.contains("panicked"), "panic: {err}");
    assert!(err.starts_with("error") && err.trim().lines().count() == 1, "not one error line: {err}");
    err
}

fn ok(cmd: &mut Command) -> String {
    String::from_utf8(cmd.assert().success().get_output().stdout.clone()).unwrap()
}

/// A 24 x 24-lenslet texture scene, its capture at `k` snapshots with 30 % vignetting and
/// calibration captures, and the calibration: `lf.npy`, `cap`, `cc`, `cal` in `dir`.
fn calibrated(dir: &Path, k: &str) {
    let p = |n: &str| dir.join(n);
    ok(slf().args(["scene", "texture", "--size", "24", "-o"]).arg(p("lf.npy")));
    ok(slf()
        .arg("simulate")
        .arg(p("lf.npy"))
        .arg("-o")
        .arg(p("cap"))
        .args(["-s", k, "--seed", "1", "--vignetting", "0.3", "--exposures", "1", "--calibration-captures"])
        .arg(p("cc")));
    ok(slf().arg("calibrate").arg(p("cc")).arg("-o").arg(p("cal")));
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

/// Item 4: `--error-map` asked for where no patch can be estimated (the response in the
/// projection) writes a map of NaN and says why (before: exit 0, no map, no line, an older
/// map left in place).
#[test]
fn an_error_map_asked_for_is_written_or_said_why_not() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    calibrated(dir.path(), "1");
    std::fs::write(p("em.npy"), b"an older map").unwrap();
    let out = ok(slf()
        .arg("decode")
        .arg(p("cap"))
        .arg("--calibration")
        .arg(p("cal"))
        .args(["--response-model", "projection", "-q", "-o"])
        .arg(p("a.npy"))
        .arg("--error-map")
        .arg(p("em.npy")));
    assert!(out.contains("error estimate: no patch could be estimated"), "{out}");
    let map = slf_host::io::lightfield::read_npy_f32_2d(&p("em.npy"), (24, 24)).unwrap();
    assert!(map.iter().all(|e| e.is_nan()), "not the NaN map");
}

/// Item 5: a decode whose light field cannot be written (`ulimit -f`) leaves none of its
/// maps either (before: the three maps were in place, written before the light field).
#[cfg(unix)]
#[test]
fn maps_do_not_outlive_a_failed_output() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    calibrated(dir.path(), "1");
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let o = |n: &str| out.join(n).display().to_string();
    // The light field is 24 x 24 x 25 x 13 f32, 749 KB; the limit 200 KB; each map a few KB.
    let script = format!(
        "ulimit -f 200; exec '{}' decode '{}' -q -o '{}' --error-map '{}' --disparity-map '{}' --member-map '{}'",
        bin().display(),
        p("cap").display(),
        o("lf.npy"),
        o("em.npy"),
        o("dm.npy"),
        o("mm.csv")
    );
    let run = Std::new("sh").args(["-c", &script]).output().unwrap();
    let err = String::from_utf8(run.stderr).unwrap();
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(err.contains("File too large"), "{err}");
    assert_eq!(files_in(&out), Vec::<String>::new());
    // Without the limit, all four.
    ok(slf()
        .arg("decode")
        .arg(p("cap"))
        .args(["-q", "-o", &o("lf.npy"), "--error-map", &o("em.npy"), "--disparity-map", &o("dm.npy")])
        .args(["--member-map", &o("mm.csv")]));
    assert_eq!(files_in(&out), ["dm.npy", "em.npy", "lf.npy", "mm.csv"]);
}

/// Item 11: `slf eval` names `--border` when it leaves SSIM too little (before: "SSIM needs
/// slices of at least 11 x 11 pixels"), and refuses an error map with a negative value
/// (before: scored, its square an error).
#[test]
fn eval_names_the_border_and_refuses_a_negative_error_map() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    ok(slf().args(["scene", "texture", "--size", "24", "-o"]).arg(p("lf.npy")));
    let e = failure(slf().arg("eval").arg(p("lf.npy")).arg(p("lf.npy")).args(["--border", "7"]));
    assert!(e.contains("--border 7 leaves 10 x 10") && e.contains("at most --border 6"), "{e}");
    let mut map = vec![0.01f32; 24 * 24];
    map[3 * 24 + 5] = -0.5;
    slf_host::io::lightfield::write_npy_f32_2d(&p("em.npy"), &map, 24, 24).unwrap();
    let e = failure(slf().arg("eval").arg(p("lf.npy")).arg(p("lf.npy")).arg("--error-map").arg(p("em.npy")));
    assert!(e.contains("at lenslet (3, 5) is -0.5") && e.contains("not negative"), "{e}");
    // NaN (a lenslet not estimated) is a value of a map.
    map[3 * 24 + 5] = f32::NAN;
    slf_host::io::lightfield::write_npy_f32_2d(&p("em.npy"), &map, 24, 24).unwrap();
    ok(slf().arg("eval").arg(p("lf.npy")).arg(p("lf.npy")).arg("--error-map").arg(p("em.npy")));
}

/// Item 11: frames and light fields with bytes after what their header states are refused
/// (before: PNG and `.npy` frames decoded, a light field read in part; PGM already refused).
#[test]
fn files_longer_than_their_header_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    ok(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(p("lf.npy")));
    // A light field with one f32 more than its header states.
    let mut bytes = std::fs::read(p("lf.npy")).unwrap();
    bytes.extend_from_slice(&1.0f32.to_le_bytes());
    std::fs::write(p("long.npy"), &bytes).unwrap();
    let e = failure(slf().arg("eval").arg(p("long.npy")).arg(p("lf.npy")));
    assert!(e.contains("long.npy: 4 bytes after the") && e.contains("values the header states"), "{e}");
    for ext in ["png", "npy"] {
        let cap = p(&format!("cap_{ext}"));
        ok(slf().arg("simulate").arg(p("lf.npy")).arg("-o").arg(&cap).args(["--format", ext]));
        ok(slf().arg("decode").arg(&cap).args(["-q", "-o"]).arg(p("x.npy")));
        // The bytes appended and the capture's record made to match, so only the reader
        // can tell.
        let name = format!("snapshot_0.{ext}");
        let frame = cap.join(&name);
        let mut f = std::fs::read(&frame).unwrap();
        f.extend_from_slice(b"junk");
        std::fs::write(&frame, &f).unwrap();
        rerecord(&cap, &name);
        let e = failure(slf().arg("decode").arg(&cap).args(["-q", "-o"]).arg(p("x.npy")));
        assert!(e.contains("4 bytes after"), "{ext}: {e}");
    }
}

/// Makes `capture.json`'s record of file `name` in `cap` match the file as it is now.
fn rerecord(cap: &Path, name: &str) {
    let json = cap.join("capture.json");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let r = slf_host::io::folder::record(cap, name).unwrap();
    for f in v["files"].as_array_mut().unwrap() {
        if f["name"] == name {
            f["bytes"] = r.bytes.into();
            f["crc32"] = r.crc32.clone().into();
        }
    }
    std::fs::write(&json, serde_json::to_string(&v).unwrap()).unwrap();
}

/// Item 11: a record's CRC in upper-case hex is the same CRC (before: "mixed or altered"); a
/// frame that is a folder is "not a regular file" (before: "mixed or altered"); a 10 MB
/// `format` string is not echoed whole.
#[test]
fn records_and_formats_are_read_as_meant() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    ok(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(p("lf.npy")));
    ok(slf().arg("simulate").arg(p("lf.npy")).arg("-o").arg(p("cap")));
    let json = p("cap").join("capture.json");
    let text = std::fs::read_to_string(&json).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    for f in v["files"].as_array_mut().unwrap() {
        let upper = f["crc32"].as_str().unwrap().to_uppercase();
        f["crc32"] = upper.into();
    }
    std::fs::write(&json, serde_json::to_string(&v).unwrap()).unwrap();
    ok(slf().arg("decode").arg(p("cap")).args(["-q", "-o"]).arg(p("x.npy")));
    // A frame that is a folder.
    let frame = p("cap").join("snapshot_0.pgm");
    std::fs::remove_file(&frame).unwrap();
    std::fs::create_dir(&frame).unwrap();
    let e = failure(slf().arg("decode").arg(p("cap")).args(["-q", "-o"]).arg(p("x.npy")));
    assert!(e.contains("snapshot_0.pgm: not a regular file (a folder)"), "{e}");
    std::fs::remove_dir(&frame).unwrap();
    // A 10 MB format string: cut in the message.
    v["format"] = "x".repeat(10_000_000).into();
    std::fs::write(&json, serde_json::to_string(&v).unwrap()).unwrap();
    let e = failure(slf().arg("decode").arg(p("cap")).args(["-q", "-o"]).arg(p("x.npy")));
    assert!(e.len() < 1000 && e.contains("(10000000 bytes)"), "{} bytes: {}", e.len(), &e[..e.len().min(300)]);
}

/// Item 11: an output name of 241 to 255 bytes (legal) is written (before: the temporary
/// file's longer name failed).
#[test]
fn a_long_output_name_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let name = format!("{}.npy", "a".repeat(251));
    assert_eq!(name.len(), 255);
    ok(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(dir.path().join(&name)));
    assert_eq!(files_in(dir.path()), [name]);
}

/// Item 8 and 12 for the command line: an output that is a FIFO is refused before the run,
/// not replaced by a file (a reader at its other end would wait for ever).
#[cfg(unix)]
#[test]
fn an_output_that_is_a_fifo_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("out.npy");
    assert!(Std::new("mkfifo").arg(&fifo).status().unwrap().success());
    let e = failure(slf().args(["scene", "smooth", "--size", "12", "-o"]).arg(&fifo));
    assert!(e.contains("not a regular file"), "{e}");
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
}

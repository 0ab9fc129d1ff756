//! Issue 51 ("nothing lost, nothing silently wrong, round 4"): each defect an outside sweep
//! found, through the `slf` command as a user meets it. Each test failed on the code before
//! its fix.

use std::path::Path;
use std::process::{Command as Std, Stdio};

use assert_cmd::Command;

fn slf() -> Command {
    Command::cargo_bin("slf").unwrap()
}

fn bin() -> std::path::PathBuf {
    assert_cmd::cargo::cargo_bin("slf")
}

/// Runs `cmd`, expects it to fail with one error line and no panic, returns the line.
fn failure(cmd: &mut Command) -> String {
    let out = cmd.assert().failure().get_output().clone();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!err.contains("panicked"), "panic: {err}");
    assert!(err.starts_with("error"), "not an error line: {err}");
    err
}

fn ok(cmd: &mut Command) -> String {
    String::from_utf8(cmd.assert().success().get_output().stdout.clone()).unwrap()
}

/// Item 10: standard output that cannot be written (a full disk, a closed pipe) is a
/// one-line error or a quiet exit, never a panic (before: exit 101 and "failed printing to
/// stdout" on `> /dev/full`, "Broken pipe" under `| head`).
#[test]
fn a_failed_stdout_is_an_error_line_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let lf = dir.path().join("s.npy");
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let out = Std::new(bin())
        .args(["scene", "smooth", "--size", "11", "-o"])
        .arg(&lf)
        .stdout(full)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.trim(), "error: cannot write to standard output: No space left on device (os error 28)");
    // A reader that has gone before the first line: a quiet exit, after the decode is
    // written (its summary comes last).
    let cap = dir.path().join("cap");
    ok(slf().arg("simulate").arg(&lf).arg("-o").arg(&cap));
    for args in [vec!["decode", "-q", "-o"], vec!["decode", "-o"]] {
        let _ = std::fs::remove_file(dir.path().join("d.npy"));
        let mut child = Std::new(bin())
            .args(&args)
            .arg(dir.path().join("d.npy"))
            .arg(&cap)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(out.status.code(), Some(0), "{err}");
        assert!(dir.path().join("d.npy").exists());
    }
}

/// Item 11: a write past `ulimit -f` fails as an error and leaves no temporary file
/// (before: SIGXFSZ ended the process, exit 153, with `.s.npy.XXXXXX.part` left).
#[cfg(unix)]
#[test]
fn a_file_size_limit_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let script = format!(
        "ulimit -f 40; exec '{}' scene smooth --size 40 -o '{}'",
        bin().display(),
        dir.path().join("s.npy").display()
    );
    let out = Std::new("sh").args(["-c", &script]).output().unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error: ") && err.contains("File too large"), "{err}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "left {left:?}");
}

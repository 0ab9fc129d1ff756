//! `docs/cli.md`, the flag reference, is the commands' own `--help`: this test makes the page
//! from `slf --help` and every command's (and `slf import`'s sub-commands'), and fails when
//! the committed page differs, so the reference cannot fall behind a flag. To write the page
//! after a flag changes:
//!
//! ```text
//! SLF_WRITE_DOCS=1 cargo test -p slf-host --test cli_reference
//! ```

use std::path::PathBuf;
use std::process::Command;

fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_slf")).args(args).arg("--help").output().expect("slf runs");
    assert!(out.status.success(), "slf {args:?} --help failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("help is UTF-8")
}

/// The names under a help text's `Commands:` heading, `help` aside.
fn commands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_owned)
        .collect()
}

fn page() -> String {
    let top = help(&[]);
    let mut out = String::from(
        "# `slf`: every command and flag\n\n\
         Made from the commands' own `--help` by `SLF_WRITE_DOCS=1 cargo test -p slf-host --test \
         cli_reference`; `cargo test` fails when this page and the binary differ. \
         `slf COMMAND --help` prints the same text.\n\n",
    );
    let mut section = |title: String, text: &str| {
        out.push_str(&format!("## {title}\n\n```text\n{}\n```\n\n", text.trim_end()));
    };
    section("`slf`".into(), &top);
    for command in commands(&top) {
        let text = help(&[&command]);
        section(format!("`slf {command}`"), &text);
        for sub in commands(&text) {
            section(format!("`slf {command} {sub}`"), &help(&[&command, &sub]));
        }
    }
    out.trim_end().to_owned() + "\n"
}

#[test]
fn the_flag_reference_is_the_commands_help() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/cli.md");
    let want = page();
    // Every command is in it, and a flag each of the main job's three steps takes.
    for needle in ["## `slf decode`", "## `slf import views`", "--preset <PRESET>", "--mask <MASK>", "--error-map"] {
        assert!(want.contains(needle), "the reference lacks {needle}");
    }
    if std::env::var_os("SLF_WRITE_DOCS").is_some() {
        std::fs::write(&path, &want).expect("docs/cli.md is writable");
        return;
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    if have != want {
        let line = have
            .lines()
            .zip(want.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(have.lines().count().min(want.lines().count()));
        panic!(
            "docs/cli.md is not the commands' --help (first difference at line {}): \
             SLF_WRITE_DOCS=1 cargo test -p slf-host --test cli_reference",
            line + 1
        );
    }
}

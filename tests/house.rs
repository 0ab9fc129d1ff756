//! The house rules a newcomer relies on, checked from the tree (issue 64):
//!
//! 1. no source file holds more than [`MAX_LINES`] lines, generated data tables aside
//!    ([`DATA_TABLES`]): a file that grows past it holds more than one idea;
//! 2. the README stays a five-minute read ([`MAX_README_LINES`]), the details in `docs/`;
//! 3. every relative link of the README and the docs pages reaches a file, and every
//!    `#anchor` a heading of it;
//! 4. every results page (`docs/results-*.md`) is stamped with the command and the commit
//!    that made it (`scripts/stamp.sh`), from a committed tree, and a page made before a
//!    change of the default decode (`docs/defaults.md`) says so in a `> Dated:` line naming
//!    the first change it predates.

mod common;

use std::path::Path;

use common::{files, root};

/// The most lines a source file may hold.
const MAX_LINES: usize = 800;
/// The most lines of the README.
const MAX_README_LINES: usize = 300;
/// Files that are data, written by a generator, not code to read.
const DATA_TABLES: &[&str] = &["host-sim/src/sim/spectra_data.rs"];

fn relative(path: &Path) -> String {
    path.strip_prefix(root()).unwrap_or(path).to_string_lossy().replace('\\', "/")
}

#[test]
fn no_source_file_holds_more_than_one_idea_by_size() {
    let mut sources = Vec::new();
    for dir in ["firmware/src", "firmware/device/src", "host-sim/src", "python/src"] {
        files(&root().join(dir), &[".rs"], &mut sources);
    }
    files(&root().join("python/slf"), &[".py"], &mut sources);
    assert!(sources.len() > 100, "the walk found {} sources: wrong root?", sources.len());
    let mut long: Vec<String> = sources
        .iter()
        .filter(|p| !DATA_TABLES.contains(&relative(p).as_str()))
        .filter_map(|p| {
            let lines = std::fs::read_to_string(p).ok()?.lines().count();
            (lines > MAX_LINES).then(|| format!("{} ({lines} lines)", relative(p)))
        })
        .collect();
    long.sort();
    assert!(long.is_empty(), "over {MAX_LINES} lines: {}", long.join(", "));
}

#[test]
fn the_readme_is_short() {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let lines = readme.lines().count();
    assert!(
        lines <= MAX_README_LINES,
        "README.md has {lines} lines; at most {MAX_README_LINES}: move details to docs/"
    );
    for command in ["cargo run --release -p slf-host -- demo", "cargo test"] {
        assert!(readme.contains(&format!("    {command}\n")), "the README does not give `{command}`");
    }
}

/// GitHub's anchor of a heading: lower case, punctuation but `-` and `_` dropped, spaces as `-`.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The text outside fenced code blocks.
fn prose(text: &str) -> String {
    let mut fenced = false;
    let mut out = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

#[test]
fn every_link_of_the_docs_reaches_its_target() {
    let mut pages = vec![root().join("README.md")];
    files(&root().join("docs"), &[".md"], &mut pages);
    let mut broken = Vec::new();
    for page in &pages {
        let text = prose(&std::fs::read_to_string(page).expect("a page"));
        let mut rest = text.as_str();
        while let Some(at) = rest.find("](") {
            rest = &rest[at + 2..];
            let Some(end) = rest.find(')') else { break };
            let link = &rest[..end];
            if link.contains("://") || link.starts_with("mailto:") || link.contains(' ') {
                continue;
            }
            let (file, hash) = link.split_once('#').unwrap_or((link, ""));
            let target = if file.is_empty() { page.clone() } else { page.parent().expect("a folder").join(file) };
            if !target.exists() {
                broken.push(format!("{}: {link} (no such file)", relative(page)));
                continue;
            }
            if !hash.is_empty() && target.extension().is_some_and(|e| e == "md") {
                let headings = std::fs::read_to_string(&target).unwrap_or_default();
                let found = prose(&headings)
                    .lines()
                    .filter_map(|l| l.strip_prefix('#'))
                    .any(|h| anchor(h.trim_start_matches('#')) == hash);
                if !found {
                    broken.push(format!("{}: {link} (no such heading)", relative(page)));
                }
            }
        }
    }
    assert!(pages.len() > 20, "found {} pages: wrong root?", pages.len());
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// `YYYY-MM-DD HH:MM` (UTC), which sorts as text in time order.
fn is_time(s: &str) -> bool {
    s.len() == 16
        && s.char_indices().all(|(i, c)| match i {
            4 | 7 => c == '-',
            10 => c == ' ',
            13 => c == ':',
            _ => c.is_ascii_digit(),
        })
}

/// A page's stamp: `> Made by `COMMAND` at COMMIT (TIME UTC)...`, as (command, commit, time).
fn stamp(line: &str) -> Option<(String, String, String)> {
    let rest = line.strip_prefix("> Made by `")?;
    let (command, rest) = rest.split_once("` at ")?;
    let (commit, rest) = rest.split_once(" (")?;
    let (time, _) = rest.split_once(" UTC)")?;
    Some((command.to_owned(), commit.to_owned(), time.to_owned()))
}

#[test]
fn every_results_page_says_what_made_it_and_when() {
    let ledger_text = std::fs::read_to_string(root().join("docs/defaults.md")).expect("docs/defaults.md");
    // The ledger's rows: | TIME | COMMIT | ISSUE | WHAT |, in time order.
    let ledger: Vec<(String, String)> = ledger_text
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.trim().trim_matches('|').split('|').map(str::trim).collect();
            (cells.len() == 4 && is_time(cells[0])).then(|| (cells[0].to_owned(), cells[1].to_owned()))
        })
        .collect();
    assert!(ledger.len() >= 10, "docs/defaults.md lists {} changes: a row's form changed?", ledger.len());
    assert!(ledger.windows(2).all(|w| w[0].0 <= w[1].0), "docs/defaults.md's rows are not in time order");

    let mut pages = Vec::new();
    files(&root().join("docs"), &[".md"], &mut pages);
    pages.retain(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("results-")));
    assert!(pages.len() >= 20, "found {} results pages", pages.len());
    let mut wrong = Vec::new();
    for page in &pages {
        let text = std::fs::read_to_string(page).expect("a page");
        let name = relative(page);
        let Some((command, commit, time)) = text.lines().take(20).find_map(stamp) else {
            wrong.push(format!("{name}: no `> Made by `COMMAND` at COMMIT (TIME UTC)` stamp in its first lines"));
            continue;
        };
        if command.trim().is_empty() || !is_time(&time) {
            wrong.push(format!("{name}: a stamp without a command or a time: {command:?} {time:?}"));
        }
        if commit.len() < 7 || !commit.chars().all(|c| c.is_ascii_hexdigit()) {
            wrong.push(format!(
                "{name}: stamped at {commit:?}, not a commit (a page from a changed tree cannot be made again)"
            ));
        }
        if let Some((_, first)) = ledger.iter().find(|(t, _)| *t > time) {
            let dated = text.lines().take(20).any(|l| l.starts_with(&format!("> Dated: made before {first}")));
            if !dated {
                wrong.push(format!("{name}: made at {time}, before the default changed at {first}, and no `> Dated: made before {first}` line"));
            }
        }
    }
    assert!(wrong.is_empty(), "results pages:\n{}", wrong.join("\n"));
}

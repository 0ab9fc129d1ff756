//! The layers of both crates, checked from their sources: a module of a lower layer never
//! names a higher one, and no modules name each other in a circle.
//!
//! How the order is defined: each crate lists its layers lowest first ([`FIRMWARE`],
//! [`HOST`]); a layer is a folder of `src/` (or a file at its top, like the firmware's
//! logging shim). A module's layer is the first folder of its path. Every `crate::` and
//! `super::` path in code (not in comments: docs may point anywhere) is resolved to the
//! module it names, and
//!
//! 1. its layer must not come after the module's own;
//! 2. it must name a layer first (`crate::solver::sl0::..`), not a re-export at the crate
//!    root (`crate::Dictionary`, `crate::sl0`): the root's old module paths are for
//!    integrators, and would hide which layer a name comes from;
//! 3. inside a layer it must name the file (`crate::solver::ball::Ball`, not
//!    `crate::solver::Ball`), and the files of a layer must not name each other in a
//!    circle.
//!
//! `use super::*` (a file's inline test module taking the file's names) is not an edge.
//! The crate roots (`lib.rs`), the firmware's `prelude.rs` and the command line (a binary
//! on top of the host library) are above every layer and are not checked.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use common::{files as files_in, root};

/// The firmware's layers, lowest first.
const FIRMWARE: &[&str] = &["log", "sensor", "operators", "solver", "decode"];
/// Root modules of the firmware above every layer.
const FIRMWARE_TOP: &[&str] = &["prelude"];
/// The host library's layers, lowest first.
const HOST: &[&str] = &["io", "sim", "decode", "train", "eval"];

/// A module: its path below `src/`, e.g. `["solver", "sl0"]` (`mod.rs` is its folder's).
type Module = Vec<String>;

/// One source file as text, with its module path.
struct Source {
    module: Module,
    file: String,
    text: String,
}

fn read_sources(src: &Path, skip: &[&str]) -> Vec<Source> {
    let mut files = Vec::new();
    files_in(src, &[".rs"], &mut files);
    let mut out = Vec::new();
    for path in files {
        let rel = path.strip_prefix(src).unwrap().to_string_lossy().replace('\\', "/");
        if rel == "lib.rs" || rel == "main.rs" || skip.iter().any(|s| rel.starts_with(s)) {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        out.push(Source { module: module_of(&rel), file: rel, text });
    }
    out
}

/// `solver/sl0.rs` -> `[solver, sl0]`; `solver/mod.rs` -> `[solver]`.
fn module_of(rel: &str) -> Module {
    let mut parts: Vec<String> = rel.trim_end_matches(".rs").split('/').map(str::to_string).collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

/// The code of `text`: comments (line, doc and block) left out and each string's contents
/// blanked, so that neither a doc link nor a message is taken for a path.
fn strip_comments(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let (mut i, mut in_str) = (0, false);
    while i < b.len() {
        let c = b[i];
        if in_str {
            if c == b'\\' && i + 1 < b.len() {
                i += 2;
                continue;
            }
            in_str = c != b'"';
            out.push(if in_str { ' ' } else { '"' });
            i += 1;
        } else if c == b'"' && !(i > 0 && b[i - 1] == b'\'' && b.get(i + 1) == Some(&b'\'')) {
            in_str = true;
            out.push('"');
            i += 1;
        } else if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            i = (i + 2..b.len()).find(|&j| b[j..].starts_with(b"*/")).map_or(b.len(), |j| j + 2);
        } else {
            // ASCII only, so that the scan below can slice the text at any byte.
            out.push(if c.is_ascii() { c as char } else { ' ' });
            i += 1;
        }
    }
    out
}

/// Every path of `code` that starts with `crate::` or `super::`, as segments (the `use`
/// trees expanded: `crate::a::{b::C, d}` gives `crate::a::b::C` and `crate::a::d`).
fn paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let at_word = i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_' || bytes[i - 1] == b':');
        let rest = &code[i..];
        if at_word && (rest.starts_with("crate::") || rest.starts_with("super::")) {
            let (tree, used) = parse_tree(rest);
            expand(&tree, Vec::new(), &mut out);
            i += used.max(1);
        } else {
            i += 1;
        }
    }
    out
}

/// A use tree: a path of segments, then nothing or a group of subtrees.
#[derive(Debug)]
struct Tree {
    segments: Vec<String>,
    group: Vec<Tree>,
}

/// Parses one path or use tree at the start of `s`; returns it and the bytes read.
fn parse_tree(s: &str) -> (Tree, usize) {
    let b = s.as_bytes();
    let mut i = 0;
    let mut segments = Vec::new();
    let mut group = Vec::new();
    loop {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        if i < b.len() && b[i] == b'{' {
            i += 1;
            loop {
                while i < b.len() && (b[i].is_ascii_whitespace() || b[i] == b',') {
                    i += 1;
                }
                if i >= b.len() || b[i] == b'}' {
                    i += 1;
                    break;
                }
                let (t, used) = parse_tree(&s[i..]);
                group.push(t);
                i += used.max(1);
            }
            break;
        }
        let start = i;
        while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
            i += 1;
        }
        if i == start {
            break;
        }
        segments.push(s[start..i].to_string());
        if s[i..].starts_with("::") {
            i += 2;
        } else {
            break;
        }
    }
    (Tree { segments, group }, i)
}

fn expand(tree: &Tree, mut prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
    prefix.extend(tree.segments.iter().cloned());
    if tree.group.is_empty() {
        out.push(prefix);
    } else {
        for t in &tree.group {
            expand(t, prefix.clone(), out);
        }
    }
}

/// The breaches of the rules in the module docs, one line each.
fn check(sources: &[Source], layers: &[&str], top: &[&str]) -> Vec<String> {
    let modules: BTreeSet<Module> = sources.iter().map(|s| s.module.clone()).collect();
    let rank = |m: &Module| layers.iter().position(|l| *l == m[0]);
    let mut problems = Vec::new();
    // Edges between files of one layer, for the cycle check.
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for s in sources {
        if top.contains(&s.module[0].as_str()) {
            continue;
        }
        let Some(own) = rank(&s.module) else {
            problems.push(format!("{}: in no layer (the layers are {layers:?})", s.file));
            continue;
        };
        for path in paths(&strip_comments(&s.text)) {
            // `use super::*;` in a file's inline test module means the file itself.
            if path.iter().all(|p| p == "super") {
                continue;
            }
            // Absolute segments below the crate root.
            let mut abs: Vec<String> = Vec::new();
            if path[0] == "crate" {
                abs.extend(path[1..].iter().cloned());
            } else {
                // `super::` from `a/b.rs` (module [a, b]) is `a`; from `a/mod.rs` it is the root.
                let mut base = s.module.clone();
                let mut rest = &path[..];
                while rest.first().is_some_and(|p| p == "super") {
                    base.pop();
                    rest = &rest[1..];
                }
                abs.extend(base);
                abs.extend(rest.iter().cloned());
            }
            let shown = path.join("::");
            // The longest prefix that is a module.
            let target = (1..=abs.len()).rev().map(|n| abs[..n].to_vec()).find(|m| modules.contains(m));
            let Some(target) = target else {
                problems.push(format!(
                    "{}: `{shown}` names no layer: name it by its layer's folder ({layers:?}), not by a re-export at the crate root",
                    s.file
                ));
                continue;
            };
            let Some(theirs) = rank(&target) else {
                problems.push(format!(
                    "{}: `{shown}` names `{}`, which is above every layer",
                    s.file,
                    target.join("::")
                ));
                continue;
            };
            if theirs > own {
                problems.push(format!(
                    "{}: `{shown}`: layer `{}` uses layer `{}`, which is above it",
                    s.file, layers[own], layers[theirs]
                ));
            } else if theirs == own && target != s.module {
                if target.len() == 1 && s.module.len() > 1 {
                    problems.push(format!(
                        "{}: `{shown}`: inside layer `{}` name the file, not the folder's re-export",
                        s.file, layers[own]
                    ));
                } else if !s.file.ends_with("mod.rs") {
                    edges.entry(s.module.clone()).or_default().insert(target);
                }
            }
        }
    }
    problems.extend(cycles(&edges));
    problems
}

/// Each circle of modules naming each other, as one line.
fn cycles(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<String> {
    // Depth-first search with colours; every back edge closes a circle.
    fn visit(
        m: &Module,
        edges: &BTreeMap<Module, BTreeSet<Module>>,
        stack: &mut Vec<Module>,
        done: &mut BTreeSet<Module>,
        out: &mut Vec<String>,
    ) {
        if done.contains(m) {
            return;
        }
        if let Some(at) = stack.iter().position(|s| s == m) {
            let circle: Vec<String> = stack[at..].iter().chain([m]).map(|m| m.join("/")).collect();
            out.push(format!("import cycle: {}", circle.join(" -> ")));
            return;
        }
        stack.push(m.clone());
        for next in edges.get(m).into_iter().flatten() {
            visit(next, edges, stack, done, out);
        }
        stack.pop();
        done.insert(m.clone());
    }
    let mut out = Vec::new();
    let mut done = BTreeSet::new();
    for m in edges.keys() {
        visit(m, edges, &mut Vec::new(), &mut done, &mut out);
    }
    out
}

#[test]
fn the_firmware_layers_use_only_the_layers_below_them() {
    let sources = read_sources(&root().join("firmware/src"), &[]);
    assert!(sources.len() > 20, "found only {} firmware modules", sources.len());
    let problems = check(&sources, FIRMWARE, FIRMWARE_TOP);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_host_library_layers_use_only_the_layers_below_them() {
    let sources = read_sources(&root().join("host-sim/src"), &["bin/"]);
    assert!(sources.len() > 20, "found only {} host modules", sources.len());
    let problems = check(&sources, HOST, &[]);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// A source tree in memory: `(file, text)` pairs.
fn tree(files: &[(&str, &str)]) -> Vec<Source> {
    files.iter().map(|(f, t)| Source { module: module_of(f), file: f.to_string(), text: t.to_string() }).collect()
}

const LAYERS: &[&str] = &["low", "high"];

#[test]
fn the_check_finds_a_lower_layer_naming_a_higher_one() {
    let files = tree(&[
        ("low/mod.rs", "pub mod a;"),
        ("low/a.rs", "use crate::{high::b::B, low::a};\nfn f() { let _ = 1; }"),
        ("high/mod.rs", "pub mod b;"),
        ("high/b.rs", "use crate::low::a::A;"),
    ]);
    let problems = check(&files, LAYERS, &[]);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].contains("low/a.rs") && problems[0].contains("crate::high::b::B"), "{problems:?}");
}

#[test]
fn the_check_finds_an_inline_path_and_a_super_path_but_not_a_comment() {
    let files = tree(&[
        ("low/a.rs", "/// [`crate::high::b`] in docs is fine\nfn f() { crate::high::b::g(); }"),
        ("low/c.rs", "// crate::high::b::g() in a comment is fine\nuse super::super::high::b::B;"),
        ("high/b.rs", "pub fn g() {}"),
    ]);
    let problems = check(&files, LAYERS, &[]);
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(problems[0].contains("low/a.rs") && problems[1].contains("low/c.rs"), "{problems:?}");
}

#[test]
fn the_check_finds_a_cycle_inside_a_layer_and_root_re_exports() {
    let files = tree(&[
        ("low/a.rs", "use crate::low::b::B;"),
        ("low/b.rs", "use super::c::C; pub struct B;"),
        ("low/c.rs", "use crate::low::a::A; use crate::Dictionary;"),
    ]);
    let problems = check(&files, LAYERS, &[]);
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(problems.iter().any(|p| p.contains("crate::Dictionary") && p.contains("names no layer")), "{problems:?}");
    assert!(problems.iter().any(|p| p.starts_with("import cycle: low/a -> low/b -> low/c -> low/a")), "{problems:?}");
}

#[test]
fn a_path_or_slashes_in_a_string_is_not_code() {
    let files = tree(&[
        ("low/a.rs", "const S: &str = \"crate::high::b // \\\" \"; const Q: u8 = b'\"'; use crate::high::c::C;"),
        ("high/b.rs", ""),
        ("high/c.rs", ""),
    ]);
    let problems = check(&files, LAYERS, &[]);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].contains("crate::high::c::C"), "{problems:?}");
}

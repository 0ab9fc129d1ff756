//! An error as the one line a user reads: the context and its causes joined by `: `, each
//! said once.
//!
//! anyhow's `{:#}` appends every cause to the message, and an error type that already
//! prints its source in its own message (an `.npy` reader's "cannot read PATH: No such
//! file", the `image` crate's decoding errors) then shows that source twice: "No such file
//! or directory (os error 2): No such file or directory (os error 2)". Here a cause whose
//! text the line already ends with is left out.

/// A number as a user would write it: `1e30` and `1e-40`, not forty digits.
pub fn number(v: f32) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) { format!("{v:e}") } else { v.to_string() }
}

/// A value read from a file, quoted for a message: whole up to [`QUOTED`] characters, else
/// its start and its length (a 10 MB `format` string was echoed whole into one line).
pub fn quoted(s: &str) -> String {
    match s.char_indices().nth(QUOTED) {
        None => format!("{s:?}"),
        Some((end, _)) => format!("{:?}... ({} bytes)", &s[..end], s.len()),
    }
}

/// The characters of a value [`quoted`] shows.
pub const QUOTED: usize = 60;

/// The longest line [`one_line`] writes, in characters: past it the line is cut and says
/// so (a file's text quoted by a message it does not cut itself).
pub const LONGEST: usize = 4000;

/// `e`'s chain on one line, without repeated causes or line breaks, at most [`LONGEST`]
/// characters.
pub fn one_line(e: &anyhow::Error) -> String {
    let line = joined(e);
    match line.char_indices().nth(LONGEST) {
        None => line,
        Some((end, _)) => format!("{}... (the message's {} bytes cut)", &line[..end], line.len()),
    }
}

fn joined(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        let text = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" ");
        if text.is_empty() || line.ends_with(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

#[cfg(test)]
mod tests {
    use crate::io::message::{LONGEST, one_line, quoted};

    #[test]
    fn long_values_are_cut() {
        let long = "x".repeat(10_000_000);
        assert_eq!(quoted("npy"), "\"npy\"");
        let q = quoted(&long);
        assert!(q.len() < 100 && q.ends_with("(10000000 bytes)"), "{q}");
        let line = one_line(&anyhow::anyhow!("format is {long:?}"));
        assert!(line.chars().count() < LONGEST + 100 && line.contains("cut"), "{}", line.len());
        // Multi-byte characters are cut at a character.
        assert!(quoted(&"é".repeat(100)).starts_with("\"é"));
    }

    #[derive(Debug)]
    struct Repeats(std::io::Error);

    impl std::fmt::Display for Repeats {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "x.npy: {}", self.0)
        }
    }

    impl std::error::Error for Repeats {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.0)
        }
    }

    #[test]
    fn a_cause_the_message_already_says_is_said_once() {
        let io = || std::io::Error::new(std::io::ErrorKind::NotFound, "No such file");
        let e = anyhow::Error::new(Repeats(io()));
        assert_eq!(format!("{e:#}"), "x.npy: No such file: No such file");
        assert_eq!(one_line(&e), "x.npy: No such file");
        // Context and a cause it does not repeat: both, joined; line breaks joined too.
        let e = anyhow::Error::new(io()).context("cannot read\n  capture.json");
        assert_eq!(one_line(&e), "cannot read capture.json: No such file");
    }
}

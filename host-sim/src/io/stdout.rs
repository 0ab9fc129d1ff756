//! Lines to standard output that fail as errors, never as panics.
//!
//! `println!` panics when standard output cannot be written: `slf scene ... > /dev/full`
//! ended in a panic (exit 101), `slf decode ... | head` in "Broken pipe". [`outln!`] writes
//! the same line and returns the failure, "cannot write to standard output: ...", which the
//! command line prints as its one-line error; a closed pipe (the reader has what it
//! wanted) ends the run quietly ([`closed_pipe`]).

use std::io::Write;

/// As `println!`, returning `anyhow::Result<()>`: `outln!("wrote {}", path.display())?`.
#[macro_export]
macro_rules! outln {
    () => {
        $crate::io::stdout::line(::std::format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::io::stdout::line(::std::format_args!($($arg)*))
    };
}

/// Writes `args` and a line break to standard output.
///
/// # Errors
/// The write's error, as "cannot write to standard output".
pub fn line(args: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.write_all(b"\n"))
        .and_then(|()| out.flush())
        .map_err(|e| anyhow::Error::new(e).context("cannot write to standard output"))
}

/// Whether `e` is a write to a pipe whose reader has gone (`slf ... | head`).
pub fn closed_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<std::io::Error>().is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe))
}

#[cfg(test)]
mod tests {
    use crate::io::stdout::closed_pipe;

    #[test]
    fn a_closed_pipe_is_told_from_other_failures() {
        let pipe = anyhow::Error::new(std::io::Error::from(std::io::ErrorKind::BrokenPipe)).context("cannot write");
        let full = anyhow::Error::new(std::io::Error::from(std::io::ErrorKind::StorageFull)).context("cannot write");
        assert!(closed_pipe(&pipe));
        assert!(!closed_pipe(&full));
    }
}

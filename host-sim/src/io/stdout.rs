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
    out.write_fmt(args).and_then(|()| out.write_all(b"\n")).and_then(|()| out.flush()).map_err(|e| {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            anyhow::Error::new(ClosedStdout)
        } else {
            anyhow::Error::new(e).context("cannot write to standard output")
        }
    })
}

/// Standard output's reader has gone (`slf ... | head`). Its own type, so that a broken
/// pipe elsewhere (an output file that is a FIFO whose reader died, a child's pipe) is
/// still the error it is and never ends the run with exit 0.
#[derive(Debug)]
pub struct ClosedStdout;

impl std::fmt::Display for ClosedStdout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("standard output was closed by its reader")
    }
}

impl std::error::Error for ClosedStdout {}

/// Whether `e` is standard output's reader going away (`slf ... | head`), and nothing else:
/// a broken pipe on any other file is a failure.
pub fn closed_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.is::<ClosedStdout>())
}

#[cfg(test)]
mod tests {
    use crate::io::stdout::{ClosedStdout, closed_pipe};

    #[test]
    fn a_closed_pipe_is_told_from_other_failures() {
        let stdout = anyhow::Error::new(ClosedStdout).context("while printing the summary");
        let full = anyhow::Error::new(std::io::Error::from(std::io::ErrorKind::StorageFull)).context("cannot write");
        // A broken pipe on an output file (a FIFO whose reader died) is a failure.
        let fifo =
            anyhow::Error::new(std::io::Error::from(std::io::ErrorKind::BrokenPipe)).context("cannot write out.npy");
        assert!(closed_pipe(&stdout));
        assert!(!closed_pipe(&full));
        assert!(!closed_pipe(&fifo));
    }
}

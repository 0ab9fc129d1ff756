//! An interrupt (Ctrl-C, SIGTERM, SIGHUP) ends a command at once, exit 130, and leaves
//! none of the temporary files and folders it was writing.
//!
//! Every result is written to a temporary beside its destination and renamed into place
//! when whole ([`crate::io::output::WholeFile`], [`crate::io::folder::WholeFolder`]). Their
//! destructors remove an unfinished temporary, but a signal ends the process without
//! running destructors: `.NAME.XXXXXX.part` files and folders were left behind, and an
//! interrupt that waited for the decode's next finished row did nothing for the seconds
//! the trials took. Here each temporary is [`track`]ed while it lives, and the handler
//! ([`install`], the command line's, on its own thread as `ctrlc` runs it) removes the
//! ones alive and exits. The Python package installs no handler: there an interrupt is
//! Python's `KeyboardInterrupt`, which stops a decode at its next tile
//! ([`crate::io::rows::Stoppable`]) and the destructors clean up.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporaries alive, by an id each.
static LIVE: Mutex<Vec<(u64, PathBuf)>> = Mutex::new(Vec::new());
static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A temporary file or folder the interrupt handler removes; untracked when dropped (the
/// temporary was renamed into place or removed by its owner).
#[derive(Debug)]
pub struct Tracked(u64);

/// Tracks `path`, a temporary file or folder, until the guard is dropped.
pub fn track(path: &Path) -> Tracked {
    let id = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    if let Ok(mut live) = LIVE.lock() {
        live.push((id, path.to_path_buf()));
    }
    Tracked(id)
}

impl Drop for Tracked {
    fn drop(&mut self) {
        if let Ok(mut live) = LIVE.lock() {
            live.retain(|(id, _)| *id != self.0);
        }
    }
}

/// Removes every tracked temporary; returns how many were removed.
pub fn remove_temporaries() -> usize {
    remove_where(|_| true)
}

/// Removes the tracked temporaries `pick` picks; returns how many were removed.
fn remove_where(pick: impl Fn(&Path) -> bool) -> usize {
    let Ok(live) = LIVE.lock() else { return 0 };
    live.iter().filter(|(_, p)| pick(p)).filter(|(_, p)| remove(p)).count()
}

/// Removes a temporary file or folder, trying again for up to [`REMOVE_TRIES`] x 10 ms: the
/// command's other threads go on writing into a folder while the handler runs, and a file
/// they add during `remove_dir_all` makes it fail ("directory not empty"; a simulate with
/// calibration captures on a loaded machine once left both of its folders so).
fn remove(p: &Path) -> bool {
    for _ in 0..REMOVE_TRIES {
        let gone = if p.is_dir() { std::fs::remove_dir_all(p) } else { std::fs::remove_file(p) };
        if gone.is_ok() || !p.exists() {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    false
}

/// The most attempts [`remove`] makes at one temporary.
const REMOVE_TRIES: usize = 50;

/// Installs the handler: on the first interrupt, the temporaries are removed, one line says
/// so, and the process exits with 130 (128 + SIGINT, as shells report an interrupt).
///
/// # Errors
/// A handler already installed, or the OS's refusal.
pub fn install() -> anyhow::Result<()> {
    ctrlc::set_handler(|| {
        remove_temporaries();
        eprintln!("error: interrupted: nothing more was written, and no partial file was left");
        std::process::exit(130);
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tracked_temporaries_are_removed_and_untracked_ones_kept() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b, c) = (dir.path().join("a.part"), dir.path().join("b.part"), dir.path().join("c.part"));
        std::fs::write(&a, b"x").unwrap();
        std::fs::create_dir(&b).unwrap();
        std::fs::write(b.join("inner"), b"x").unwrap();
        std::fs::write(&c, b"x").unwrap();
        let (_ga, _gb) = (track(&a), track(&b));
        drop(track(&c));
        // This test's own (other tests' temporaries, tracked in the same process, stay).
        assert_eq!(remove_where(|p| p.starts_with(dir.path())), 2);
        assert!(!a.exists() && !b.exists() && c.exists());
    }
}

//! An interrupt (Ctrl-C, SIGTERM, SIGHUP) ends a command at once, exit 130, and leaves
//! none of the temporary files and folders it was writing.
//!
//! Every result is written to a temporary beside its destination and renamed into place
//! when whole ([`crate::io::output::WholeFile`], [`crate::io::folder::WholeFolder`]). Their
//! destructors remove an unfinished temporary, but a signal ends the process without
//! running destructors: `.NAME.XXXXXX.part` files and folders were left behind, and an
//! interrupt that waited for the decode's next finished row did nothing for the seconds
//! the trials took. Here each temporary is made and tracked in one step ([`make`]) while it lives, and the handler
//! ([`install`], the command line's, on its own thread as `ctrlc` runs it) removes the
//! ones alive and exits. The Python package installs no handler: there an interrupt is
//! Python's `KeyboardInterrupt`, which stops a decode at its next tile
//! ([`crate::io::rows::Stoppable`]) and the destructors clean up.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The process's one [`Temporaries`], which the command line's handler sweeps.
static TEMPORARIES: Temporaries = Temporaries::new();

/// The temporaries alive and the state of an interrupt's handling.
///
/// The command goes on while the handler runs, and two races came from it (each about one
/// run in twenty on a loaded machine): a temporary made just before or during the sweep
/// and tracked after it was left behind (a scene's output, a simulate's calibration
/// folder); and the command, failing because its temporaries were gone, ended the process
/// with 1 before the handler's 130 ("cannot read .c.XXXXXX.part/snapshot_0.pgm"). So a
/// temporary is made and tracked in one step under `live`, which the handler holds from
/// its sweep to the process's end ([`Temporaries::make`]), and [`settle`] waits for the
/// handler.
struct Temporaries {
    /// The temporaries alive, by an id each.
    live: Mutex<Vec<(u64, PathBuf)>>,
    next: AtomicU64,
    /// Held by the handler from the interrupt to the process's end.
    handling: Mutex<()>,
    /// Set once the handler holds `handling`.
    interrupted: AtomicBool,
}

impl Temporaries {
    const fn new() -> Self {
        Self {
            live: Mutex::new(Vec::new()),
            next: AtomicU64::new(0),
            handling: Mutex::new(()),
            interrupted: AtomicBool::new(false),
        }
    }

    /// Makes a temporary with `create` and tracks it (at `path` of it), in one step under
    /// `live`: a temporary exists only tracked, and none is made once the handler swept.
    fn make<T>(
        &self,
        create: impl FnOnce() -> std::io::Result<T>,
        path: impl Fn(&T) -> &Path,
    ) -> std::io::Result<(T, u64)> {
        let mut live = self.live.lock().map_err(|_| std::io::Error::other("the temporaries' list was poisoned"))?;
        if self.interrupted.load(Ordering::SeqCst) {
            return Err(std::io::Error::new(std::io::ErrorKind::Interrupted, "interrupted"));
        }
        let made = create()?;
        let id = self.next.fetch_add(1, Ordering::Relaxed);
        live.push((id, path(&made).to_path_buf()));
        Ok((made, id))
    }

    fn untrack(&self, id: u64) {
        if let Ok(mut live) = self.live.lock() {
            live.retain(|(i, _)| *i != id);
        }
    }

    /// The handler's body: every tracked temporary removed, then `end`, with `handling`
    /// and `live` held throughout (`end` exits the process with them held, so nothing is
    /// made after the sweep) and `interrupted` set first.
    fn on_interrupt(&self, end: impl FnOnce()) {
        let _held = self.handling.lock();
        self.interrupted.store(true, Ordering::SeqCst);
        let live = self.live.lock();
        if let Ok(live) = &live {
            for (_, p) in live.iter() {
                remove(p);
            }
        }
        end();
    }

    /// Returns at once unless an interrupt is being handled; then waits for the handler's
    /// end.
    fn settle(&self) {
        if self.interrupted.load(Ordering::SeqCst) {
            let _wait = self.handling.lock();
        }
    }
}

/// A temporary file or folder the interrupt handler removes; untracked when dropped (the
/// temporary was renamed into place or removed by its owner).
#[derive(Debug)]
pub struct Tracked(u64);

/// Makes a temporary file or folder with `create` and tracks it, at `path` of it, until
/// the guard is dropped.
///
/// # Errors
/// `create`'s, or `Interrupted` once an interrupt is being handled.
pub fn make<T>(
    create: impl FnOnce() -> std::io::Result<T>,
    path: impl Fn(&T) -> &Path,
) -> std::io::Result<(T, Tracked)> {
    TEMPORARIES.make(create, path).map(|(t, id)| (t, Tracked(id)))
}

impl Drop for Tracked {
    fn drop(&mut self) {
        TEMPORARIES.untrack(self.0);
    }
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
        TEMPORARIES.on_interrupt(|| {
            eprintln!("error: interrupted: nothing more was written, and no partial file was left");
            std::process::exit(130);
        });
    })?;
    Ok(())
}

/// Waits, when an interrupt is being handled, for the handler to end the process: `main`
/// calls this before it reports how the command ended, since the command may have failed
/// only because the handler removed its temporaries.
pub fn settle() {
    TEMPORARIES.settle();
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    fn file(p: &Path) -> std::io::Result<PathBuf> {
        std::fs::write(p, b"x").map(|()| p.to_path_buf())
    }

    #[test]
    fn tracked_temporaries_are_removed_and_untracked_ones_kept() {
        let t = Temporaries::new();
        let dir = tempfile::tempdir().unwrap();
        let (a, b, c) = (dir.path().join("a.part"), dir.path().join("b.part"), dir.path().join("c.part"));
        let folder = |p: &Path| std::fs::create_dir(p).and_then(|()| file(&p.join("inner"))).map(|_| p.to_path_buf());
        let (_, _ia) = t.make(|| file(&a), |p| p).unwrap();
        let (_, _ib) = t.make(|| folder(&b), |p| p).unwrap();
        let (_, ic) = t.make(|| file(&c), |p| p).unwrap();
        t.untrack(ic);
        let mut ended = false;
        t.on_interrupt(|| ended = true);
        assert!(ended && !a.exists() && !b.exists() && c.exists());
    }

    /// Once the handler has swept, no temporary is made; `settle` returns only after the
    /// handler's end (there, the process's exit), not in the middle of its sweep; before
    /// any interrupt it returns at once.
    #[test]
    fn nothing_is_made_after_the_sweep_and_settling_waits_for_the_handler() {
        let t = Arc::new(Temporaries::new());
        t.settle();
        let ended = Arc::new(AtomicBool::new(false));
        let handler = {
            let (t, ended) = (Arc::clone(&t), Arc::clone(&ended));
            std::thread::spawn(move || {
                t.on_interrupt(|| {
                    std::thread::sleep(std::time::Duration::from_millis(200));
                    ended.store(true, Ordering::SeqCst);
                })
            })
        };
        while !t.interrupted.load(Ordering::SeqCst) {
            std::thread::yield_now();
        }
        let dir = tempfile::tempdir().unwrap();
        let late = dir.path().join("late.part");
        let made = t.make(|| file(&late), |p| p);
        assert!(made.is_err() && !late.exists(), "a temporary was made during the handling");
        t.settle();
        assert!(ended.load(Ordering::SeqCst), "settle returned before the handler's end");
        handler.join().unwrap();
    }
}

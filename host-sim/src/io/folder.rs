//! Folders written whole, and the checksums that tell a folder's files belong together.
//!
//! Each file of a capture or calibration is written whole ([`crate::io::output`]); a folder
//! was not: `slf calibrate -o` over an old calibration that failed after `dark.npy` left
//! new dark levels beside old flats, and `slf simulate -o` over an old capture that failed
//! on its second frame left one new frame beside the old description. Both decoded with
//! exit 0. Here a folder is written into a temporary folder beside its target
//! ([`WholeFolder`]) and renamed into place when every file is in; a failure removes the
//! temporary and leaves the old folder as it was.
//!
//! A folder's description also records each file's size and CRC-32 ([`FileRecord`]), and
//! loading checks them ([`verify`]), so a frame copied in from another capture of the same
//! size, or a file edited by hand, is refused with its name. Folders written before the
//! records existed load with a note.

use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use serde::{Deserialize, Serialize};

/// What a folder holds, and so what an existing folder at the target may be replaced.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// Files: the description (`capture.json`, `calibration.json`), the files of fixed
    /// names beside it, and the ones its `frames` or `files` name that are names of this
    /// kind (the function): a stray `capture.json` naming `thesis.tex` does not make the
    /// folder's `thesis.tex` one to replace.
    Files(&'static str, &'static [&'static str], fn(&str) -> bool),
    /// Folders, each holding the description (a set of calibration captures).
    Folders(&'static str),
    /// A store: the description at its top, and folders (its arrays) each holding the
    /// description too (a Zarr store's `zarr.json`).
    Store(&'static str),
}

/// The names a folder of [`Kind::Files`] may hold: the description, `fixed`, and what the
/// description at `target` names in `frames` and `files`.
fn named_files(target: &Path, description: &str, fixed: &[&str], ours: fn(&str) -> bool) -> Vec<String> {
    let mut names: Vec<String> = std::iter::once(description).chain(fixed.iter().copied()).map(String::from).collect();
    // A description is small: one larger than 64 MiB (a capture's own cap) is not read,
    // and names nothing.
    let path = target.join(description);
    let small = fs::metadata(&path).is_ok_and(|m| m.is_file() && m.len() <= 64 << 20);
    let text = if small { fs::read_to_string(&path).unwrap_or_default() } else { String::new() };
    if let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) {
        let frames = v["frames"].as_array().into_iter().flatten().filter_map(|f| f.as_str());
        let files = v["files"].as_array().into_iter().flatten().filter_map(|f| f["name"].as_str());
        names.extend(frames.chain(files).filter(|n| ours(n)).map(String::from));
    }
    names
}

/// A folder being written: files go into [`Self::path`], and [`Self::persist`] puts it at
/// its target. Dropped without `persist`, it removes itself.
pub struct WholeFolder {
    temp: tempfile::TempDir,
    target: PathBuf,
    kind: Kind,
    /// Removed by an interrupt's handler too ([`crate::io::interrupt`]).
    _tracked: crate::io::interrupt::Tracked,
}

impl WholeFolder {
    /// A temporary folder beside `target` (its parent folders created), after checking
    /// that `target` is new, empty, or a folder of `kind` that may be replaced whole.
    ///
    /// # Errors
    /// An empty path, a target that is a file or holds anything else than a folder of
    /// `kind` would (a user's other files are never removed), or the I/O error.
    pub fn create(target: &Path, kind: Kind) -> Result<Self> {
        ensure!(!target.as_os_str().is_empty(), "an empty path names no folder to write");
        replaceable(target, target, kind)?;
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        fs::create_dir_all(&parent).with_context(|| format!("cannot create {}", parent.display()))?;
        let name = target.file_name().map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
        let (temp, _tracked) = crate::io::interrupt::make(
            || tempfile::Builder::new().prefix(&format!(".{name}.")).suffix(".part").tempdir_in(&parent),
            |t| t.path(),
        )
        .with_context(|| format!("cannot create a folder in {}", parent.display()))?;
        Ok(Self { temp, target: target.to_path_buf(), kind, _tracked })
    }

    /// Where the files go until [`Self::persist`].
    pub fn path(&self) -> &Path {
        self.temp.path()
    }

    /// Puts the folder at its target: an old folder there is moved aside, the new one
    /// renamed in, and the old one removed. At no moment does the target hold a mix; a
    /// crash between the two renames leaves the old folder beside it as `.NAME.old.*`.
    /// The old folder is looked at again once aside: a file put into it since
    /// [`Self::create`] looked (during a long run) puts it back, and nothing is replaced.
    ///
    /// # Errors
    /// The I/O error; the old folder is put back when the new one cannot take its place,
    /// or when it now holds what the kind does not.
    pub fn persist(self) -> Result<()> {
        let Self { temp, target, kind, _tracked } = self;
        let target_text = target.display().to_string();
        if fs::symlink_metadata(&target).is_err() {
            let temp = temp.keep();
            return fs::rename(&temp, &target).with_context(|| format!("cannot put {target_text} in place"));
        }
        let parent = temp.path().parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        let old = tempfile::Builder::new()
            .prefix(&format!(".{}.old.", target.file_name().map_or_else(String::new, |n| n.to_string_lossy().into())))
            .tempdir_in(&parent)
            .with_context(|| format!("cannot create a folder in {}", parent.display()))?;
        // The old folder's place: a fresh name (the empty folder made for it is replaced).
        let aside = old.keep();
        fs::remove_dir(&aside).with_context(|| format!("cannot use {}", aside.display()))?;
        fs::rename(&target, &aside).with_context(|| format!("cannot move the old {target_text} aside"))?;
        // What is aside is what gets removed: looked at there, after the rename, so a file
        // added to the target during the run is never removed with it.
        if let Err(e) = replaceable(&aside, &target, kind) {
            let back = fs::rename(&aside, &target);
            return Err(e).with_context(|| match back {
                Ok(()) => {
                    format!("{target_text} changed during the run; it is left as it was, and nothing was written")
                }
                Err(b) => format!("{target_text} changed during the run; it is now {} ({b})", aside.display()),
            });
        }
        let temp = temp.keep();
        if let Err(e) = fs::rename(&temp, &target) {
            let _ = fs::rename(&aside, &target);
            let _ = fs::remove_dir_all(&temp);
            return Err(e).with_context(|| format!("cannot put {target_text} in place"));
        }
        fs::remove_dir_all(&aside)
            .with_context(|| format!("cannot remove the old {target_text} (now {})", aside.display()))
    }
}

/// Checks that `target` may be written whole: absent, an empty folder, or a folder of
/// `kind` holding nothing else; `dir` is where it is now (the target, or the old folder
/// moved aside), `target` the name the messages give.
fn replaceable(dir: &Path, target: &Path, kind: Kind) -> Result<()> {
    let Ok(meta) = fs::symlink_metadata(dir) else { return Ok(()) };
    let what = match kind {
        Kind::Files(d, _, _) => format!("a folder of {d} and the files it names"),
        Kind::Folders(d) => format!("a folder of folders holding {d}"),
        Kind::Store(d) => format!("a store ({d} and folders holding {d})"),
    };
    let allowed = match kind {
        Kind::Files(d, fixed, ours) => named_files(dir, d, fixed, ours),
        Kind::Folders(_) | Kind::Store(_) => Vec::new(),
    };
    ensure!(meta.is_dir(), "{} is not a folder: the output is {what}", target.display());
    let mut described = false;
    for entry in fs::read_dir(dir).with_context(|| format!("cannot read {}", target.display()))? {
        let entry = entry.with_context(|| format!("cannot read {}", target.display()))?;
        let (path, t) = (target.join(entry.file_name()), entry.file_type()?);
        let fits = match kind {
            Kind::Files(d, _, _) => {
                described |= entry.file_name() == d;
                t.is_file() && allowed.iter().any(|n| entry.file_name() == n.as_str())
            }
            Kind::Folders(d) => {
                described = true;
                t.is_dir() && entry.path().join(d).is_file()
            }
            Kind::Store(d) if entry.file_name() == d => {
                described = true;
                t.is_file()
            }
            Kind::Store(d) => t.is_dir() && entry.path().join(d).is_file(),
        };
        if !fits {
            bail!(
                "{} holds {}, which {what} does not: the output replaces the folder whole, so choose a new or empty \
                 folder",
                target.display(),
                path.display()
            );
        }
    }
    if let Kind::Files(d, _, _) | Kind::Store(d) = kind {
        ensure!(
            described || fs::read_dir(dir).map(|mut r| r.next().is_none()).unwrap_or(false),
            "{} holds files but no {d}: the output replaces the folder whole, so choose a new or empty folder",
            target.display()
        );
    }
    Ok(())
}

/// One file of a folder as its description records it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileRecord {
    /// The file's name in the folder.
    pub name: String,
    /// Its size in bytes.
    pub bytes: u64,
    /// Its CRC-32 (IEEE), as 8 hexadecimal digits.
    pub crc32: String,
}

/// The record of the file `name` in `dir`, as written.
///
/// # Errors
/// The I/O error, with the file.
pub fn record(dir: &Path, name: &str) -> Result<FileRecord> {
    let (bytes, crc) = checksum(&dir.join(name))?;
    Ok(FileRecord { name: name.into(), bytes, crc32: format!("{crc:08x}") })
}

fn checksum(path: &Path) -> Result<(u64, u32)> {
    let mut file = fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut hasher = crc32fast::Hasher::new();
    let mut buf = vec![0u8; 1 << 16];
    let mut bytes = 0u64;
    loop {
        let n = file.read(&mut buf).with_context(|| format!("cannot read {}", path.display()))?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
        bytes += n as u64;
    }
    Ok((bytes, hasher.finalize()))
}

/// Checks the files of `dir` against their records in `description` (the file that holds
/// them, for messages): each `names` file must have a record, and each record's size
/// (checked first, from the file's metadata) and CRC-32 must match.
///
/// # Errors
/// The first file that is missing from the records, or differs, named.
pub fn verify(dir: &Path, description: &Path, records: &[FileRecord], names: &[&str]) -> Result<()> {
    for name in names {
        ensure!(
            records.iter().any(|r| r.name == *name),
            "{}: records no size and checksum for {name}",
            description.display()
        );
    }
    for r in records {
        ensure!(
            Path::new(&r.name).components().all(|c| matches!(c, std::path::Component::Normal(_))),
            "{}: records a file {} outside its folder",
            description.display(),
            crate::io::message::quoted(&r.name)
        );
        let path = dir.join(&r.name);
        let meta = fs::metadata(&path).with_context(|| format!("cannot read {}", path.display()))?;
        ensure!(meta.is_file(), "{}: not a regular file ({})", path.display(), crate::io::output::file_kind(&meta));
        // The record's hex in either case (a hand-edited or other tool's record).
        let recorded = u32::from_str_radix(&r.crc32, 16).ok().filter(|_| r.crc32.len() == 8).with_context(|| {
            format!(
                "{}: records CRC-32 {} for {}: not 8 hex digits",
                description.display(),
                crate::io::message::quoted(&r.crc32),
                r.name
            )
        })?;
        ensure!(
            meta.len() == r.bytes,
            "{}: {} bytes, but {} records {}: the folder is mixed or the file altered",
            path.display(),
            meta.len(),
            description.display(),
            r.bytes
        );
        let (_, crc) = checksum(&path)?;
        ensure!(
            crc == recorded,
            "{}: CRC-32 {crc:08x}, but {} records {}: the folder is mixed or the file altered",
            path.display(),
            description.display(),
            r.crc32
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_is_replaced_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("cap");
        let kind = Kind::Files("capture.json", &["a", "b"], |n| n.ends_with(".pgm"));
        let write = |files: &[(&str, &str)], keep: bool| -> Result<()> {
            let f = WholeFolder::create(&target, kind)?;
            for (n, t) in files {
                fs::write(f.path().join(n), t)?;
            }
            if keep { f.persist() } else { Ok(()) }
        };
        write(&[("capture.json", "1"), ("a", "old")], true).unwrap();
        // Dropped before persist: the old folder as it was, no temporary beside it.
        write(&[("capture.json", "2"), ("a", "new")], false).unwrap();
        assert_eq!(fs::read_to_string(target.join("a")).unwrap(), "old");
        write(&[("capture.json", "2"), ("b", "new")], true).unwrap();
        assert!(!target.join("a").exists());
        assert_eq!(fs::read_to_string(target.join("b")).unwrap(), "new");
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, ["cap"]);
        // A folder holding anything else is never replaced: a file it does not name, a
        // folder; what the description's frames name is its own.
        let desc = r#"{"frames": ["f.pgm"]}"#;
        fs::write(target.join("capture.json"), desc).unwrap();
        fs::write(target.join("f.pgm"), "frame").unwrap();
        write(&[("capture.json", desc), ("f.pgm", "new frame")], true).unwrap();
        fs::write(target.join("notes.txt"), "mine").unwrap();
        let e = write(&[("capture.json", desc)], true).unwrap_err().to_string();
        assert!(e.contains("notes.txt") && e.contains("choose a new or empty folder"), "{e}");
        fs::remove_file(target.join("notes.txt")).unwrap();
        fs::create_dir(target.join("sub")).unwrap();
        let e = write(&[("capture.json", "3")], true).unwrap_err().to_string();
        assert!(e.contains("sub") && e.contains("choose a new or empty folder"), "{e}");
        assert_eq!(fs::read_to_string(target.join("f.pgm")).unwrap(), "new frame");
        let other = dir.path().join("other");
        fs::create_dir(&other).unwrap();
        fs::write(other.join("x.npy"), "x").unwrap();
        let e = WholeFolder::create(&other, kind).err().unwrap().to_string();
        assert!(e.contains("x.npy") && e.contains("choose a new or empty folder"), "{e}");
        // Files of the fixed names alone, without the description: not a folder of this kind.
        fs::remove_file(other.join("x.npy")).unwrap();
        fs::write(other.join("a"), "a").unwrap();
        let e = WholeFolder::create(&other, kind).err().unwrap().to_string();
        assert!(e.contains("holds files but no capture.json"), "{e}");
        assert!(WholeFolder::create(Path::new(""), kind).err().unwrap().to_string().contains("empty path"));
    }

    #[test]
    fn a_file_added_during_the_run_is_never_removed() {
        // Issue 65, item 10: the old folder was checked when the run began and removed whole
        // at its end, with a file the user put into it meanwhile.
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("cap");
        let kind = Kind::Files("capture.json", &["a"], |_| false);
        fs::create_dir(&target).unwrap();
        fs::write(target.join("capture.json"), "old").unwrap();
        let f = WholeFolder::create(&target, kind).unwrap();
        fs::write(f.path().join("capture.json"), "new").unwrap();
        fs::write(target.join("notes.txt"), "mine").unwrap();
        let e = format!("{:#}", f.persist().unwrap_err());
        assert!(e.contains("changed during the run") && e.contains("notes.txt"), "{e}");
        assert!(!e.contains(".old."), "names the folder moved aside: {e}");
        assert_eq!(fs::read_to_string(target.join("notes.txt")).unwrap(), "mine");
        assert_eq!(fs::read_to_string(target.join("capture.json")).unwrap(), "old");
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, ["cap"], "a temporary or the old folder left beside it");
    }

    #[test]
    fn records_find_a_changed_or_swapped_file() {
        let dir = tempfile::tempdir().unwrap();
        fs::write(dir.path().join("a"), "hello").unwrap();
        fs::write(dir.path().join("b"), "world").unwrap();
        let records = vec![record(dir.path(), "a").unwrap(), record(dir.path(), "b").unwrap()];
        // The CRC-32 of "hello", as any implementation gives it.
        assert_eq!(records[0], FileRecord { name: "a".into(), bytes: 5, crc32: "3610a686".into() });
        let desc = dir.path().join("d.json");
        verify(dir.path(), &desc, &records, &["a", "b"]).unwrap();
        fs::write(dir.path().join("b"), "w0rld").unwrap();
        let e = verify(dir.path(), &desc, &records, &["a"]).unwrap_err().to_string();
        assert!(e.contains("b: CRC-32") && e.contains("mixed or the file altered"), "{e}");
        fs::write(dir.path().join("b"), "world!").unwrap();
        assert!(verify(dir.path(), &desc, &records, &[]).unwrap_err().to_string().contains("6 bytes"));
        assert!(verify(dir.path(), &desc, &records[..1], &["b"]).unwrap_err().to_string().contains("for b"));
    }
}

//! Writing results: a file is written whole or not at all, and never over a file the same
//! run reads or writes elsewhere.
//!
//! - [`write_whole`]: the bytes go to a temporary file in the destination's folder, which
//!   is renamed over the destination only once everything is written and flushed. A
//!   failed write (disk full, `ulimit -f`, an encoder error) leaves the previous file as it
//!   was and no temporary file behind: a file that exists is whole. The rename is atomic on
//!   one file system, which the same folder guarantees.
//! - [`Outputs`]: a run's inputs and outputs, checked before the run does its work: no
//!   output is an input (`slf decode CAP -o CAP/capture.json` would destroy the capture),
//!   no two outputs are the same file, and every output's folder is writable. Paths are
//!   compared resolved (symbolic links followed, `..` removed) and, where the file exists,
//!   by device and inode, so a hard link or a second spelling does not slip through.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};

/// The longest file name most file systems take, in bytes.
const MAX_NAME: usize = 255;

/// What a file that is not a regular file is, for a message.
pub fn file_kind(meta: &fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_block_device() || t.is_char_device() {
            return "a device";
        }
    }
    if meta.is_dir() {
        "a folder"
    } else if meta.is_file() {
        "a regular file"
    } else {
        "not a file"
    }
}

/// Writes `path` whole: `write` fills a buffered temporary file in the same folder, which
/// then replaces `path`. On any error nothing at `path` changes.
///
/// # Errors
/// What `write` returns, or the I/O error, with the path.
pub fn write_whole(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    stage(path, write)?.persist()
}

/// As [`write_whole`], but left in its temporary file: the caller persists it once the
/// run's other outputs are written too, so that a run that fails later (the light field's
/// file past `ulimit -f`) leaves none of its results, not the small ones alone. Dropped
/// unpersisted, the temporary file is removed.
///
/// # Errors
/// What `write` returns, or the I/O error, with the path.
pub fn stage(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<WholeFile> {
    let mut whole = WholeFile::create(path)?;
    let failed = || format!("cannot write {}", path.display());
    let mut out = BufWriter::new(whole.file());
    write(&mut out).with_context(failed)?;
    out.flush().with_context(failed)?;
    drop(out);
    Ok(whole)
}

/// A file written whole in any order (a streamed decode's rows at their offsets): a
/// temporary file in the destination's folder until [`Self::persist`] renames it over the
/// destination. Dropped without it (an error, a panic, an interrupt the run turned into
/// an error), the temporary file is removed and the destination is as it was.
pub struct WholeFile {
    tmp: tempfile::NamedTempFile,
    path: PathBuf,
    /// Removed by an interrupt's handler too ([`crate::io::interrupt`]).
    _tracked: crate::io::interrupt::Tracked,
}

impl WholeFile {
    /// The temporary file for `path`, empty.
    ///
    /// # Errors
    /// `path` is a folder or not a file name, or its folder takes no new file.
    pub fn create(path: &Path) -> Result<Self> {
        let failed = || format!("cannot write {}", path.display());
        let name = path.file_name().with_context(|| format!("cannot write {}: not a file name", path.display()))?;
        ensure!(!path.is_dir(), "cannot write {}: a folder", path.display());
        regular_if_there(path).with_context(failed)?;
        // ".NAME.XXXXXX.part": 13 bytes more than the name, so a legal name of up to 255
        // bytes is cut to what the file system takes (the temporary's name is only seen
        // if the run is killed).
        let mut prefix = std::ffi::OsString::from(".");
        if name.len() <= MAX_NAME - 13 {
            prefix.push(name);
        } else {
            let mut cut = String::new();
            for c in name.to_string_lossy().chars() {
                if cut.len() + c.len_utf8() > MAX_NAME - 13 {
                    break;
                }
                cut.push(c);
            }
            prefix.push(cut);
        }
        prefix.push(".");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".part");
        // A temporary file is made 0600; the result is an ordinary file, 0666 less the
        // umask as `File::create` makes it (as uv's `tempfile_in` does).
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let (tmp, _tracked) =
            crate::io::interrupt::make(|| builder.tempfile_in(parent(path)), |t| t.path()).with_context(failed)?;
        Ok(Self { tmp, path: path.to_path_buf(), _tracked })
    }

    /// The temporary file, to write (and seek) in.
    pub fn file(&mut self) -> &mut fs::File {
        self.tmp.as_file_mut()
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The temporary file's own path, for a writer that opens the file by name (the HDF5
    /// writer); it is renamed over [`Self::path`] by [`Self::persist`].
    pub fn part_path(&self) -> &Path {
        self.tmp.path()
    }

    /// Syncs the temporary file and renames it over the destination.
    ///
    /// # Errors
    /// The I/O error, with the path (the temporary file is removed).
    pub fn persist(self) -> Result<()> {
        let failed = || format!("cannot write {}", self.path.display());
        self.tmp.as_file().sync_all().with_context(failed)?;
        self.tmp.persist(&self.path).map_err(|e| e.error).with_context(failed)?;
        Ok(())
    }
}

/// Writes `bytes` to `path` whole ([`write_whole`]).
///
/// # Errors
/// The I/O error, with the path.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_whole(path, |w| Ok(w.write_all(bytes)?))
}

/// Writes an 8-bit RGB image (`raw`: rows of `width` pixels, 3 bytes each) as PNG, whole
/// ([`write_whole`]).
///
/// # Errors
/// A buffer of the wrong size, or the I/O error, with the path.
pub fn write_png_rgb(path: &Path, width: u32, height: u32, raw: &[u8]) -> Result<()> {
    use image::ImageEncoder;
    ensure!(raw.len() as u64 == 3 * u64::from(width) * u64::from(height), "image buffer of the wrong size");
    write_whole(path, |out| {
        image::codecs::png::PngEncoder::new(out).write_image(raw, width, height, image::ExtendedColorType::Rgb8)?;
        Ok(())
    })
}

fn parent(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A path as the file system sees it: resolved where it exists, else its folder resolved
/// and its name appended (an output that is not written yet); the path as given when its
/// folder does not exist either.
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = fs::canonicalize(path) {
        return p;
    }
    match (fs::canonicalize(parent(path)), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

#[cfg(unix)]
fn identity(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn identity(_: &Path) -> Option<(u64, u64)> {
    None
}

/// One file of a run: the path as the user gave it (for messages) and as it resolves.
#[derive(Clone, Debug)]
struct Named {
    given: PathBuf,
    what: String,
    at: PathBuf,
    id: Option<(u64, u64)>,
    /// A folder written whole (a Zarr store): what lies inside it is its.
    folder: bool,
}

impl Named {
    fn new(given: &Path, what: &str) -> Self {
        Self { given: given.to_path_buf(), what: what.into(), at: resolved(given), id: identity(given), folder: false }
    }

    fn same(&self, other: &Named) -> bool {
        self.at == other.at || matches!((self.id, other.id), (Some(a), Some(b)) if a == b)
    }

    /// `other` is this folder output or lies inside it.
    fn holds(&self, other: &Named) -> bool {
        self.same(other) || (self.folder && other.at.starts_with(&self.at))
    }
}

/// A run's files: what it reads and what it writes, checked against each other
/// ([`Outputs::check`]) before the work starts.
#[derive(Clone, Debug, Default)]
pub struct Outputs {
    inputs: Vec<Named>,
    outputs: Vec<Named>,
}

impl Outputs {
    /// No files yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// A file the run reads (`what` names it in messages: "the capture's frame").
    #[must_use]
    pub fn input(mut self, path: &Path, what: &str) -> Self {
        self.inputs.push(Named::new(path, what));
        self
    }

    /// Files the run reads.
    #[must_use]
    pub fn inputs<P: AsRef<Path>>(self, paths: impl IntoIterator<Item = P>, what: &str) -> Self {
        paths.into_iter().fold(self, |s, p| s.input(p.as_ref(), what))
    }

    /// A file the run writes (`what` names its flag: "-o").
    #[must_use]
    pub fn output(mut self, path: &Path, what: &str) -> Self {
        self.outputs.push(Named::new(path, what));
        self
    }

    /// A folder the run writes whole (a Zarr store): no input or other output may lie
    /// inside it, and it is checked as a folder ([`crate::io::folder::WholeFolder`] checks
    /// what an old one holds when it is made).
    #[must_use]
    pub fn folder_output(mut self, path: &Path, what: &str) -> Self {
        self.outputs.push(Named { folder: true, ..Named::new(path, what) });
        self
    }

    /// Files the run writes (an `Option` for an output that may not be asked for).
    #[must_use]
    pub fn outputs<P: AsRef<Path>>(self, paths: impl IntoIterator<Item = P>, what: &str) -> Self {
        paths.into_iter().fold(self, |s, p| s.output(p.as_ref(), what))
    }

    /// Checks that no output is an input or another output, and that every output can be
    /// written (not a folder, its folder exists and takes a new file). Creates nothing.
    ///
    /// # Errors
    /// One line naming the two flags and the file.
    pub fn check(&self) -> Result<()> {
        self.check_distinct()?;
        for o in &self.outputs {
            if o.folder { folder_writable(&o.given) } else { writable(&o.given) }
                .with_context(|| format!("cannot write {} {} (checked before the run)", o.what, o.given.display()))?;
        }
        Ok(())
    }

    /// As [`Self::check`] without the writability check, for outputs in a folder the run
    /// has not made yet.
    ///
    /// # Errors
    /// One line naming the two flags and the file.
    pub fn check_distinct(&self) -> Result<()> {
        for (i, o) in self.outputs.iter().enumerate() {
            if let Some(inp) = self.inputs.iter().find(|inp| o.holds(inp)) {
                let is = if o.same(inp) { "is" } else { "holds" };
                bail!(
                    "{} {} {is} {} {}: an output may not be a file the run reads (it would be destroyed)",
                    o.what,
                    o.given.display(),
                    inp.what,
                    inp.given.display()
                );
            }
            if let Some(other) = self.outputs[..i].iter().find(|other| other.holds(o) || o.holds(other)) {
                let (a, b) = if o.holds(other) { (o, other) } else { (other, o) };
                if a.same(b) {
                    bail!(
                        "{} {} and {} {} are the same file: each output needs its own",
                        other.what,
                        other.given.display(),
                        o.what,
                        o.given.display()
                    );
                }
                bail!(
                    "{} {} is inside {} {}, which is written whole: each output needs its own place",
                    b.what,
                    b.given.display(),
                    a.what,
                    a.given.display()
                );
            }
        }
        Ok(())
    }
}

/// Fails if the folder `path` cannot be written whole: a file there, a missing parent, a
/// parent that refuses a new folder. Creates nothing.
fn folder_writable(path: &Path) -> Result<()> {
    ensure!(!path.as_os_str().is_empty(), "an empty path names no folder");
    if let Ok(meta) = fs::symlink_metadata(path) {
        ensure!(meta.is_dir(), "not a folder ({})", file_kind(&meta));
    }
    let dir = parent(path);
    ensure!(dir.is_dir(), "the folder {} does not exist", dir.display());
    crate::io::interrupt::make(|| tempfile::Builder::new().prefix(".slf-check.").tempdir_in(dir), |t| t.path())
        .context("the folder takes no new folder")?;
    Ok(())
}

/// Fails if `path` cannot be written: a folder, a missing parent, a folder that refuses a
/// new file. Leaves an existing file as it was and nothing new behind.
fn writable(path: &Path) -> Result<()> {
    ensure!(!path.is_dir(), "a folder, not a file");
    let dir = parent(path);
    ensure!(dir.is_dir(), "the folder {} does not exist", dir.display());
    crate::io::interrupt::make(|| tempfile::Builder::new().prefix(".slf-check.").tempfile_in(dir), |t| t.path())
        .context("the folder takes no new file")?;
    if let Some(meta) = regular_if_there(path)? {
        ensure!(!meta.permissions().readonly(), "read-only");
    }
    Ok(())
}

/// `path`'s metadata if it exists, checked to be a regular file's: a FIFO, a socket or a
/// device would be replaced by the rename, not written (the reader at the other end of a
/// FIFO would wait for ever, and the name would become a plain file).
fn regular_if_there(path: &Path) -> Result<Option<fs::Metadata>> {
    match fs::metadata(path) {
        Ok(meta) => {
            ensure!(meta.is_file(), "not a regular file ({})", file_kind(&meta));
            Ok(Some(meta))
        }
        Err(_) => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_the_previous_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.npy");
        fs::write(&p, b"previous").unwrap();
        let e = write_whole(&p, |w| {
            w.write_all(b"half of the new")?;
            bail!("disk full")
        })
        .unwrap_err();
        assert!(format!("{e:#}").contains("disk full"), "{e:#}");
        assert_eq!(fs::read(&p).unwrap(), b"previous");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1, "a temporary file was left");
        write_bytes(&p, b"new").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = |p: &Path| fs::metadata(p).unwrap().permissions().mode() & 0o777;
            let plain = dir.path().join("plain");
            fs::File::create(&plain).unwrap();
            assert_eq!(mode(&p), mode(&plain), "an output's mode is File::create's");
            fs::remove_file(&plain).unwrap();
        }
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn an_output_may_be_neither_an_input_nor_another_output() {
        let dir = tempfile::tempdir().unwrap();
        let cap = dir.path().join("cap");
        fs::create_dir(&cap).unwrap();
        let json = cap.join("capture.json");
        fs::write(&json, b"{}").unwrap();
        let out = dir.path().join("out.npy");
        // Another spelling of the same file.
        let other = cap.join("..").join("cap").join("capture.json");
        let e = Outputs::new().input(&json, "the capture's").output(&other, "-o").check().unwrap_err();
        assert!(e.to_string().contains("may not be a file the run reads"), "{e}");
        // A hard link to it.
        let link = dir.path().join("link.json");
        fs::hard_link(&json, &link).unwrap();
        assert!(Outputs::new().input(&json, "the capture's").output(&link, "-o").check().is_err());
        // Two outputs, one file.
        let e = Outputs::new().output(&out, "-o").output(&out, "--disparity-map").check().unwrap_err();
        assert!(e.to_string().contains("are the same file"), "{e}");
        // Distinct: fine, and nothing is created.
        Outputs::new().input(&json, "the capture's").output(&out, "-o").check().unwrap();
        assert!(!out.exists());
        // A missing folder or a folder as the output.
        assert!(Outputs::new().output(&dir.path().join("nope/out.npy"), "-o").check().is_err());
        assert!(Outputs::new().output(&cap, "-o").check().is_err());
    }
}

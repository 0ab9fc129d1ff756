//! A raw frame read from its file a band of rows at a time ([`PagedFrame`]), so a decode
//! holds a few bands of each snapshot, never the frame; or from rows made as they are read
//! ([`FrameRows`]: a calibration's correction, the aligned reading's crop).
//!
//! Every pass of a decode goes down the frame (the trials' pilots, the white balance's
//! sums, the streamed decode and its held-out twin, the baselines' lenslet rows), so the
//! bands it reads are near each other: a small cache of bands, the least recently used
//! one dropped for the next, reads each band about once a pass. The cache is shared by the
//! decode's threads behind one read-write lock; each thread also keeps the last
//! [`RECENT`] bands it read ([`thread_local::ThreadLocal`], shared handles to the cache's
//! values), so a run of samples in a band it just read takes no lock. Taking the shared
//! lock once a run cost a default decode 12 % more CPU than a held frame on 2 threads
//! (the lock's count is written by every reader: its cache line moved between the cores at
//! every run).
//!
//! The file stays open from [`PagedFrame::open_npy`], [`PagedFrame::open_pgm`] or
//! [`PagedFrame::open_png`] on: a frame renamed or deleted during
//! the decode is still the frame that was checked. A read that fails later (a disk error,
//! a file cut short by another program) reads as no sample and is kept; the decode then
//! fails with it ([`PagedFrame::error`]) instead of flagging the pixels.

use std::cell::RefCell;
use std::fmt;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, RwLock};

use anyhow::Result;
use slf_firmware::Frame;
use thread_local::ThreadLocal;

use crate::io::npy::NpyError;
use crate::io::png_rows::PngRows;
use crate::io::row_reader::RowReader;

/// A band holds at least this many rows, and at least [`BAND_BYTES`].
pub const MIN_BAND_ROWS: usize = 32;

/// A band's least size in bytes: a narrow frame's bands are taller, so the cache's index
/// stays short.
pub const BAND_BYTES: usize = 64 << 10;

/// The cache holds this many bytes of a frame, and at least [`MIN_BANDS`] + 4 bands a
/// worker thread (each thread's tile or pilot reads from two bands at most).
pub const CACHE_BYTES: usize = 8 << 20;

/// The fewest bands the cache holds.
pub const MIN_BANDS: usize = 8;

/// The bands each thread keeps at hand past the shared cache: a tile or a pilot reads from
/// two bands at most.
pub const RECENT: usize = 2;

/// Where a paged frame's rows come from: its file ([`RowReader`]), or rows made from
/// another frame's as they are read (a calibration's correction, the aligned reading's
/// crop), so no whole frame is made.
pub trait FrameRows: Send + Sync + fmt::Debug {
    /// `(rows, cols)`.
    fn size(&self) -> (usize, usize);

    /// Rows `first..first + out.len() / cols` into `out`.
    ///
    /// # Errors
    /// A read that fails, naming the file and the rows.
    fn read_rows(&self, first: usize, out: &mut [u16]) -> Result<()>;
}

impl FrameRows for RowReader {
    fn size(&self) -> (usize, usize) {
        RowReader::size(self)
    }

    fn read_rows(&self, first: usize, out: &mut [u16]) -> Result<()> {
        self.read_u16(first, out)
    }
}

impl FrameRows for PngRows {
    fn size(&self) -> (usize, usize) {
        PngRows::size(self)
    }

    fn read_rows(&self, first: usize, out: &mut [u16]) -> Result<()> {
        PngRows::read_rows(self, first, out)
    }
}

/// A raw frame of `u16` values read from its source a band of rows at a time.
pub struct PagedFrame {
    source: Arc<dyn FrameRows>,
    rows: usize,
    cols: usize,
    band_rows: usize,
    capacity: usize,
    cache: RwLock<Cache>,
    /// Each thread's last bands read: handles to values the cache held when they were read
    /// (a band's values never change, so one the cache has since dropped is still right).
    recent: ThreadLocal<RefCell<Recent>>,
    /// Bumped at each band read: a band's `used` is the count when it was last read from.
    clock: AtomicU64,
    /// Bands read from the source so far.
    loads: AtomicU64,
    /// The first read that failed, as one line.
    error: Mutex<Option<String>>,
}

/// The bands held, and where each band of the frame is held (`NONE` where it is not).
struct Cache {
    slot_of: Vec<u32>,
    slots: Vec<Slot>,
}

struct Slot {
    band: usize,
    used: AtomicU64,
    values: Arc<[u16]>,
}

/// A thread's last [`RECENT`] bands, the newest first.
#[derive(Default)]
struct Recent {
    bands: [Option<(usize, Arc<[u16]>)>; RECENT],
}

impl Recent {
    fn find(&self, band: usize) -> Option<&[u16]> {
        self.bands.iter().flatten().find(|(b, _)| *b == band).map(|(_, v)| &v[..])
    }

    fn put(&mut self, band: usize, values: Arc<[u16]>) {
        self.bands.rotate_right(1);
        self.bands[0] = Some((band, values));
    }
}

const NONE: u32 = u32::MAX;

impl PagedFrame {
    /// Opens a `.npy` raw frame (`uint16`, two axes in C order) of `rows x cols`: its header
    /// and length are checked now, its values read as the decode asks for them. `None` for
    /// a file that is valid but not stored so (Fortran order): the caller reads it whole.
    ///
    /// # Errors
    /// The file and what is wrong with it, as [`crate::io::npy::read_checked`] says it.
    pub fn open_npy(path: &Path, (rows, cols): (usize, usize)) -> Result<Option<Self>, NpyError> {
        let reader = RowReader::open_npy(path, |s, element| {
            crate::io::lightfield::check_frame_header(s, element, Some((rows, cols)))
        })?;
        Ok(reader.map(|r| Self::new(Arc::new(r))))
    }

    /// Opens a binary PGM raw frame of `rows x cols` ([`RowReader::open_pgm`]: every check
    /// of a whole read, now), its values read as the decode asks. The file's MAXVAL beside.
    ///
    /// # Errors
    /// The file and what is wrong with it.
    pub fn open_pgm(path: &Path, size: (usize, usize)) -> Result<(Self, u32)> {
        let (reader, top) = RowReader::open_pgm(path, Some(size))?;
        Ok((Self::new(Arc::new(reader)), top))
    }

    /// Opens a grey 8- or 16-bit PNG raw frame of `rows x cols` ([`PngRows`]): its header
    /// checked and every row decoded once now (a damaged stream is refused before the
    /// decode), its rows decoded again as the decode asks, one pass down the file for each
    /// pass of the decode. `None` for a PNG read whole (interlaced, another depth). Its
    /// largest value (255 or 65535) beside.
    ///
    /// # Errors
    /// The file and what is wrong with it.
    pub fn open_png(path: &Path, size: (usize, usize)) -> Result<Option<(Self, u32)>> {
        let Some((reader, top)) = PngRows::open(path, Some(size))? else { return Ok(None) };
        reader.check_all()?;
        Ok(Some((Self::new(Arc::new(reader)), top)))
    }

    /// The frame `source` reads, paged, with the decode's cache.
    pub fn new(source: Arc<dyn FrameRows>) -> Self {
        let (_, cols) = source.size();
        let row_bytes = cols.max(1) * 2;
        let band_rows = MIN_BAND_ROWS.max(BAND_BYTES.div_ceil(row_bytes));
        let threads = rayon::current_num_threads();
        let capacity = (MIN_BANDS + 4 * threads).max(CACHE_BYTES / (band_rows * row_bytes));
        Self::with_bands(source, band_rows, capacity)
    }

    fn with_bands(source: Arc<dyn FrameRows>, band_rows: usize, capacity: usize) -> Self {
        let band_rows = band_rows.max(1);
        let (rows, cols) = source.size();
        let bands = rows.div_ceil(band_rows);
        Self {
            source,
            rows,
            cols,
            band_rows,
            capacity: capacity.clamp(1, bands.max(1)),
            cache: RwLock::new(Cache { slot_of: vec![NONE; bands], slots: Vec::new() }),
            recent: ThreadLocal::new(),
            clock: AtomicU64::new(0),
            loads: AtomicU64::new(0),
            error: Mutex::new(None),
        }
    }

    /// This frame with bands of `band_rows` rows and at most `capacity` of them held (tests
    /// and benchmarks of the cache; a fresh cache).
    pub fn with_cache(&self, band_rows: usize, capacity: usize) -> Self {
        Self::with_bands(self.source.clone(), band_rows, capacity)
    }

    /// Where the rows come from (shared: a frame made from this one reads it past its
    /// cache).
    pub fn source(&self) -> Arc<dyn FrameRows> {
        self.source.clone()
    }

    /// Bands read from the source so far (a pass reads each band about once).
    pub fn loads(&self) -> u64 {
        self.loads.load(Ordering::Relaxed)
    }

    /// The most bytes the cache holds, with each thread's [`RECENT`] bands at hand (at
    /// most that many past the shared cache's).
    pub fn cache_bytes(&self) -> usize {
        (self.capacity + RECENT * rayon::current_num_threads()) * self.band_rows * self.cols * 2
    }

    /// The first read that failed since the frame was opened, as one line naming the file.
    pub fn error(&self) -> Option<String> {
        self.error.lock().ok().and_then(|e| e.clone())
    }

    /// Reads rows `first..first + out.len() / cols` from the source into `out`, past the
    /// cache (a pass that reads each row once: the no-light check, the saturation count).
    ///
    /// # Errors
    /// The file and the rows that could not be read.
    pub fn read_rows(&self, first: usize, out: &mut [u16]) -> Result<()> {
        self.source.read_rows(first, out)
    }

    /// Calls `f` with the held values of `row` from column `col` on, reading the row's
    /// band first if it is not held; `None` where it cannot be read (the error kept).
    #[inline]
    fn with_row<R>(&self, row: usize, col: usize, f: impl FnOnce(&[u16]) -> R) -> Option<R> {
        let band = row / self.band_rows;
        let at = (row - band * self.band_rows) * self.cols + col;
        let recent = self.recent.get_or_default();
        if let Ok(r) = recent.try_borrow()
            && let Some(values) = r.find(band)
        {
            return values.get(at..).map(f);
        }
        let values = self.band(band)?;
        let out = values.get(at..).map(f);
        if let Ok(mut r) = recent.try_borrow_mut() {
            r.put(band, values);
        }
        out
    }

    /// Band `band`'s values from the shared cache, read from the source first if it is not
    /// held; `None` where it cannot be read (the error kept).
    fn band(&self, band: usize) -> Option<Arc<[u16]>> {
        {
            let cache = self.cache.read().ok()?;
            if let Some(slot) = cache.held(band) {
                let now = self.clock.load(Ordering::Relaxed);
                if slot.used.load(Ordering::Relaxed) != now {
                    slot.used.store(now, Ordering::Relaxed);
                }
                return Some(slot.values.clone());
            }
        }
        let mut cache = self.cache.write().ok()?;
        if cache.held(band).is_none() {
            let first = band * self.band_rows;
            let rows = self.band_rows.min(self.rows - first);
            let mut values = vec![0u16; rows * self.cols];
            if let Err(e) = self.read_rows(first, &mut values) {
                if let Ok(mut kept) = self.error.lock() {
                    kept.get_or_insert_with(|| crate::io::message::one_line(&e));
                }
                return None;
            }
            self.loads.fetch_add(1, Ordering::Relaxed);
            let used = AtomicU64::new(self.clock.fetch_add(1, Ordering::Relaxed) + 1);
            let slot = Slot { band, used, values: values.into() };
            if cache.slots.len() < self.capacity {
                let i = cache.slots.len() as u32;
                cache.slots.push(slot);
                cache.slot_of[band] = i;
            } else {
                // The least recently used band gives its place.
                let i = (0..cache.slots.len()).min_by_key(|&i| cache.slots[i].used.load(Ordering::Relaxed))?;
                let old = cache.slots[i].band;
                cache.slot_of[old] = NONE;
                cache.slots[i] = slot;
                cache.slot_of[band] = i as u32;
            }
        }
        cache.held(band).map(|slot| slot.values.clone())
    }
}

impl Cache {
    fn held(&self, band: usize) -> Option<&Slot> {
        let i = *self.slot_of.get(band)?;
        if i == NONE { None } else { self.slots.get(i as usize) }
    }
}

impl Frame for PagedFrame {
    fn size(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    fn sample(&self, i: usize) -> Option<f32> {
        let cols = self.cols;
        let (row, col) = (i.checked_div(cols)?, i.checked_rem(cols)?);
        if row >= self.rows {
            return None;
        }
        self.with_row(row, col, |v| v.first().map(|&x| f32::from(x)))?
    }

    fn read_run(&self, start: usize, out: &mut [f32]) -> Option<()> {
        let cols = self.cols;
        let (row, col) = (start.checked_div(cols)?, start.checked_rem(cols)?);
        if row >= self.rows || col + out.len() > cols {
            return None;
        }
        self.with_row(row, col, |v| {
            let run = v.get(..out.len())?;
            for (o, &x) in out.iter_mut().zip(run) {
                *o = f32::from(x);
            }
            Some(())
        })?
    }
}

/// A copy shares the source (an open file), with a cache of its own.
impl Clone for PagedFrame {
    fn clone(&self) -> Self {
        Self::with_bands(self.source.clone(), self.band_rows, self.capacity)
    }
}

impl fmt::Debug for PagedFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "PagedFrame({:?}, bands of {} rows)", self.source, self.band_rows)
    }
}

#[cfg(test)]
mod tests {
    use std::fs::File;
    use std::path::PathBuf;

    use super::*;

    fn frame(dir: &Path, rows: usize, cols: usize) -> (PathBuf, Vec<u16>) {
        let data: Vec<u16> = (0..rows * cols).map(|i| (i * 7919 % 65521) as u16).collect();
        let path = dir.join("f.npy");
        crate::io::lightfield::write_npy_u16_2d(&path, &data, rows, cols).unwrap();
        (path, data)
    }

    /// Samples and runs read through a cache of two bands of 3 rows equal the frame's,
    /// in any order, and a pass down the frame reads each band once.
    #[test]
    fn a_small_cache_reads_what_the_file_holds_in_any_order() {
        let dir = tempfile::tempdir().unwrap();
        let (rows, cols) = (17, 5);
        let (path, data) = frame(dir.path(), rows, cols);
        let f = PagedFrame::open_npy(&path, (rows, cols)).unwrap().unwrap().with_cache(3, 2);
        assert_eq!(f.size(), (rows, cols));
        for (i, &x) in data.iter().enumerate() {
            assert_eq!(f.sample(i), Some(f32::from(x)), "sample {i}");
        }
        assert_eq!(f.loads(), 6, "17 rows in bands of 3, each read once going down");
        // Backwards and scattered: still the file's values.
        let mut out = [0.0f32; 3];
        for row in (0..rows).rev().chain([0, 16, 8, 1, 15]) {
            f.read_run(row * cols + 2, &mut out).unwrap();
            let want: Vec<f32> = data[row * cols + 2..row * cols + 5].iter().map(|&x| f32::from(x)).collect();
            assert_eq!(out.to_vec(), want, "row {row}");
        }
        assert_eq!(f.sample(rows * cols), None);
        assert!(f.read_run(cols - 1, &mut out).is_none(), "a run past its row's end");
        assert!(f.error().is_none());
    }

    /// A thread's recent bands are read without the shared cache and stay right when the
    /// cache has dropped them (a cache of one band): a band read again just after is not
    /// read from the file again, the third band back is; two frames of one file, read in
    /// turn, each read their own cache.
    #[test]
    fn a_threads_recent_bands_are_its_own_and_stay_right() {
        let dir = tempfile::tempdir().unwrap();
        let (rows, cols) = (12, 4);
        let (path, data) = frame(dir.path(), rows, cols);
        let f = PagedFrame::open_npy(&path, (rows, cols)).unwrap().unwrap().with_cache(3, 1);
        let at = |row: usize| row * cols + 1;
        let want = |row: usize| Some(f32::from(data[at(row)]));
        assert_eq!(f.sample(at(0)), want(0));
        assert_eq!(f.sample(at(4)), want(4)); // band 1: the cache drops band 0
        assert_eq!(f.loads(), 2);
        assert_eq!(f.sample(at(1)), want(1), "band 0, dropped by the cache, read from the thread's own");
        assert_eq!(f.loads(), 2, "not read again");
        assert_eq!(f.sample(at(7)), want(7)); // band 2 pushes band 0 out of the thread's two
        assert_eq!(f.sample(at(2)), want(2));
        assert_eq!(f.loads(), 4, "band 0 read again once neither held it");
        let g = f.with_cache(3, 1);
        for row in [0, 11, 1, 10] {
            assert_eq!(f.sample(at(row)), want(row), "f, row {row}");
            assert_eq!(g.sample(at(row)), want(row), "g, row {row}");
        }
        assert_eq!(g.loads(), 2, "g read its two bands itself");
        // Other threads read the same values through their own.
        std::thread::scope(|s| {
            for t in 0..3 {
                let (f, data) = (&f, &data);
                s.spawn(move || {
                    for i in (t..rows * cols).step_by(3) {
                        assert_eq!(f.sample(i), Some(f32::from(data[i])), "thread {t}, sample {i}");
                    }
                });
            }
        });
    }

    /// A file cut short after it was opened reads as no sample, and the error names it.
    #[test]
    fn a_read_that_fails_later_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _) = frame(dir.path(), 40, 4);
        let f = PagedFrame::open_npy(&path, (40, 4)).unwrap().unwrap().with_cache(4, 2);
        assert!(f.sample(0).is_some());
        File::options().write(true).open(&path).unwrap().set_len(200).unwrap();
        assert_eq!(f.sample(39 * 4), None);
        let e = f.error().unwrap();
        assert!(e.contains("f.npy") && e.contains("rows 36..40"), "{e}");
    }

    /// The header is checked when the frame is opened: another size is refused.
    #[test]
    fn another_size_is_refused_at_open() {
        let dir = tempfile::tempdir().unwrap();
        let (path, _) = frame(dir.path(), 6, 4);
        let e = PagedFrame::open_npy(&path, (4, 6)).unwrap_err().to_string();
        assert!(e.contains("frame is 6 x 4, the capture's frames are 4 x 6"), "{e}");
    }
}

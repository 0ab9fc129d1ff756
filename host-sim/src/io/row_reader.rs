//! A two-axis array stored row-major in a file, read a few rows at a time ([`RowReader`]):
//! a `.npy` file's body (the reading twin of [`crate::io::npy_rows`]) or a binary PGM's
//! (8- or 16-bit). The raw frames a decode pages ([`crate::io::paged_frame`]), read whole
//! too ([`crate::io::frame_file`]: one set of checks), and a calibration's dark and flat
//! maps, which a corrected decode reads beside them, never whole. [`by_bands`]: a pass
//! over such an array holding one band.
//!
//! The file stays open from [`RowReader::open_npy`] or [`RowReader::open_pgm`] on: a file renamed or deleted during the
//! decode is still the file that was checked; one cut short reads as an error naming the
//! rows.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anyhow::{Result, anyhow};

use crate::io::npy::{self, Element, NpyError, NpyErrorKind};

/// How a value is stored: a `.npy` file's element, or a byte (an 8-bit PGM).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stored {
    Npy(Element),
    U8,
}

impl Stored {
    fn size(self) -> usize {
        match self {
            Stored::Npy(e) => e.size() as usize,
            Stored::U8 => 1,
        }
    }
}

/// A row-major two-axis array in a file, open for reading rows; a copy shares the file.
#[derive(Clone, Debug)]
pub struct RowReader {
    path: Arc<PathBuf>,
    file: Arc<Mutex<File>>,
    /// The first value's byte.
    body: u64,
    /// Big-endian values.
    swap: bool,
    stored: Stored,
    rows: usize,
    cols: usize,
}

impl RowReader {
    /// Opens `path`: its header is read and given to `check` (shape, element type), and
    /// its length checked; nothing of the body is read. `None` for a valid file stored in
    /// Fortran order (rows not contiguous): the caller reads it whole.
    ///
    /// # Errors
    /// The file and what is wrong with it, as [`npy::read_checked`] says it; a shape of
    /// other than two axes.
    pub fn open_npy(
        path: &Path,
        check: impl FnOnce(&[usize], Element) -> Result<(), String>,
    ) -> Result<Option<Self>, NpyError> {
        let err = |kind| NpyError::new(path, kind);
        // Look before opening: opening a FIFO blocks until a writer comes.
        let meta = std::fs::metadata(path).map_err(|e| err(NpyErrorKind::Io(e)))?;
        if !meta.is_file() {
            return Err(err(NpyErrorKind::NotAFile));
        }
        let mut file = File::open(path).map_err(|e| err(NpyErrorKind::Io(e)))?;
        let mut two = None;
        let layout = npy::read_layout(&mut std::io::BufReader::new(&mut file), meta.len(), |s, element| {
            check(s, element)?;
            match *s {
                [rows, cols] => {
                    two = Some((rows, cols));
                    Ok(())
                }
                _ => Err(format!("has {} axes, not 2", s.len())),
            }
        })
        .map_err(err)?;
        let Some((rows, cols)) = two else { return Err(err(NpyErrorKind::Magic)) };
        if layout.fortran_order && rows > 1 && cols > 1 {
            return Ok(None);
        }
        Ok(Some(Self {
            path: Arc::new(path.to_path_buf()),
            file: Arc::new(Mutex::new(file)),
            body: layout.body,
            swap: layout.swap,
            stored: Stored::Npy(layout.element),
            rows,
            cols,
        }))
    }

    /// A binary PGM (P5): its header (MAXVAL in 1..=65535; with `expect`, its size against
    /// the capture's before anything else is read), its length and every value against
    /// its MAXVAL checked now, in one pass of bands; its values read later as asked, or
    /// whole ([`crate::io::frame_file::read_frame`] reads it so). Its MAXVAL beside.
    ///
    /// # Errors
    /// The file and what is wrong with it.
    pub fn open_pgm(path: &Path, expect: Option<(usize, usize)>) -> Result<(Self, u32)> {
        use image::codecs::pnm::{PnmDecoder, PnmSubtype, SampleEncoding};
        let len = crate::io::file_checks::regular_file(path, u64::MAX, "")?;
        let file = File::open(path).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
        let decoder = PnmDecoder::new(std::io::BufReader::new(file))
            .map_err(|e| anyhow!("{}: not a PGM file: {e}", path.display()))?;
        let (mut reader, header) = decoder.into_inner();
        if header.subtype() != PnmSubtype::Graymap(SampleEncoding::Binary) {
            return Err(anyhow!(
                "{}: a raw frame is a binary PGM (P5), this file is {:?}",
                path.display(),
                header.subtype()
            ));
        }
        let (w, h, top) = (header.width(), header.height(), header.maximal_sample());
        if !(1..=65535).contains(&top) {
            return Err(anyhow!("{}: MAXVAL {top} out of 1..=65535", path.display()));
        }
        crate::io::file_checks::check_size(path, (u64::from(h), u64::from(w)), expect)?;
        let (rows, cols) = (h as usize, w as usize);
        let stored = if top > 255 { Stored::Npy(Element::U16) } else { Stored::U8 };
        let body = reader.stream_position().map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
        let need = u64::from(w) * u64::from(h) * stored.size() as u64;
        if need > len {
            return Err(anyhow!("{}: {w} x {h} pixels need {need} bytes, the file has {len}", path.display()));
        }
        if body + need > len {
            return Err(anyhow!("{}: truncated: {w} x {h} pixels promised", path.display()));
        }
        // A frame file holds one image: bytes after it mean a writer that disagrees with
        // the header (a wrong size, a second image), so the file is refused, not half read.
        if body + need < len {
            return Err(anyhow!(
                "{}: bytes after the {w} x {h} pixels the header promises (the file is longer than its image)",
                path.display()
            ));
        }
        let file = reader.into_inner();
        let this = Self {
            path: Arc::new(path.to_path_buf()),
            file: Arc::new(Mutex::new(file)),
            body,
            swap: true,
            stored,
            rows,
            cols,
        };
        // Every value against MAXVAL, a band at a time.
        by_bands(
            (rows, cols),
            64,
            |first, part: &mut [u16]| this.read_u16(first, part),
            |first, part| match part.iter().position(|&x| u32::from(x) > top) {
                Some(i) => {
                    let p = first * cols + i;
                    Err(anyhow!(
                        "{}: pixel ({}, {}) is {}, above MAXVAL {top}",
                        path.display(),
                        p / cols,
                        p % cols,
                        part[i]
                    ))
                }
                None => Ok(()),
            },
        )?;
        Ok((this, top))
    }

    /// `(rows, cols)`.
    pub fn size(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The bytes of rows `first..first + n`, `n` whole rows in `values` values.
    fn bytes(&self, first: usize, values: usize) -> Result<Vec<u8>> {
        let (rows, cols) = (self.rows, self.cols.max(1));
        let n = values / cols;
        let size = self.stored.size();
        if !values.is_multiple_of(cols) || first + n > rows {
            return Err(anyhow!("{}: rows {first}..{} of a {rows} x {cols} array", self.path.display(), first + n));
        }
        let mut bytes = vec![0u8; values * size];
        let mut read = || -> std::io::Result<()> {
            let mut f = self.file.lock().map_err(|_| std::io::Error::other("a reader panicked"))?;
            f.seek(SeekFrom::Start(self.body + (first * cols * size) as u64))?;
            f.read_exact(&mut bytes)
        };
        read().map_err(|e| anyhow!("{}: cannot read rows {first}..{}: {e}", self.path.display(), first + n))?;
        Ok(bytes)
    }

    /// Reads rows `first..first + out.len() / cols` of a `uint16` file into `out`.
    ///
    /// # Errors
    /// Rows past the end, a file of floats, or a read that fails: the file and the rows.
    pub fn read_u16(&self, first: usize, out: &mut [u16]) -> Result<()> {
        match self.stored {
            Stored::Npy(Element::U16) => {
                let bytes = self.bytes(first, out.len())?;
                for (o, b) in out.iter_mut().zip(bytes.chunks_exact(2)) {
                    let b = [b[0], b[1]];
                    *o = if self.swap { u16::from_be_bytes(b) } else { u16::from_le_bytes(b) };
                }
            }
            Stored::U8 => {
                let bytes = self.bytes(first, out.len())?;
                for (o, &b) in out.iter_mut().zip(&bytes) {
                    *o = u16::from(b);
                }
            }
            Stored::Npy(_) => return Err(anyhow!("{}: holds floats, not uint16", self.path.display())),
        }
        Ok(())
    }

    /// Reads rows `first..first + out.len() / cols` into `out` as `f32` (`float64` values
    /// rounded, as [`npy::read_checked`] reads them whole).
    ///
    /// # Errors
    /// As [`Self::read_u16`].
    pub fn read_f32(&self, first: usize, out: &mut [f32]) -> Result<()> {
        let bytes = self.bytes(first, out.len())?;
        match self.stored {
            Stored::U8 => {
                for (o, &b) in out.iter_mut().zip(&bytes) {
                    *o = f32::from(b);
                }
            }
            Stored::Npy(Element::U16) => {
                for (o, b) in out.iter_mut().zip(bytes.chunks_exact(2)) {
                    let b = [b[0], b[1]];
                    *o = f32::from(if self.swap { u16::from_be_bytes(b) } else { u16::from_le_bytes(b) });
                }
            }
            Stored::Npy(Element::F32) => {
                for (o, b) in out.iter_mut().zip(bytes.chunks_exact(4)) {
                    let b = [b[0], b[1], b[2], b[3]];
                    *o = if self.swap { f32::from_be_bytes(b) } else { f32::from_le_bytes(b) };
                }
            }
            Stored::Npy(Element::F64) => {
                for (o, b) in out.iter_mut().zip(bytes.chunks_exact(8)) {
                    let b: [u8; 8] = [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
                    *o = (if self.swap { f64::from_be_bytes(b) } else { f64::from_le_bytes(b) }) as f32;
                }
            }
        }
        Ok(())
    }
}

/// A pass over a `rows x cols` array a band of `band` rows at a time, holding one band:
/// `read(first, values)` fills the band of rows from `first` on, `f(first, values)` is given
/// it. The shape of every streamed check and copy of a frame or a map.
///
/// # Errors
/// The first that `read` or `f` returns.
pub fn by_bands<T: Copy + Default>(
    (rows, cols): (usize, usize),
    band: usize,
    mut read: impl FnMut(usize, &mut [T]) -> Result<()>,
    mut f: impl FnMut(usize, &[T]) -> Result<()>,
) -> Result<()> {
    let band = band.clamp(1, rows.max(1));
    let mut values = vec![T::default(); band * cols];
    for first in (0..rows).step_by(band) {
        let part = &mut values[..band.min(rows - first) * cols];
        read(first, part)?;
        f(first, part)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows read from a float32 file equal the file read whole, at any row; rows past the
    /// end are refused with the file's name.
    #[test]
    fn rows_equal_the_whole_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.npy");
        let (rows, cols) = (7, 3);
        let data: Vec<f32> = (0..rows * cols).map(|i| i as f32 * 0.37 - 2.0).collect();
        crate::io::lightfield::write_npy_f32_2d(&path, &data, rows, cols).unwrap();
        let m = RowReader::open_npy(&path, |_, _| Ok(())).unwrap().unwrap();
        assert_eq!(m.size(), (rows, cols));
        for first in 0..rows {
            let mut out = vec![0.0f32; (rows - first) * cols];
            m.read_f32(first, &mut out).unwrap();
            assert_eq!(out, data[first * cols..], "from row {first}");
        }
        let e = m.read_f32(6, &mut [0.0; 6]).unwrap_err().to_string();
        assert!(e.contains("m.npy") && e.contains("rows 6..8"), "{e}");
        assert!(m.read_u16(0, &mut [0; 3]).is_err(), "floats read as uint16");
    }

    /// A PGM's rows, 16- or 8-bit, equal the values written; a faulty one is refused, naming
    /// the file and the fault: another size than the capture's, a value above MAXVAL past
    /// the first band, bytes after the image, a body cut short by one value and by half.
    #[test]
    fn a_pgm_is_read_by_rows_and_refused_where_it_is_faulty() {
        let dir = tempfile::tempdir().unwrap();
        let (rows, cols) = (70, 3);
        let pgm = |name: &str, top: u32, values: &[u16], extra: &[u8]| {
            let mut bytes = format!("P5\n{cols} {rows}\n{top}\n").into_bytes();
            for &v in values {
                if top > 255 { bytes.extend(v.to_be_bytes()) } else { bytes.push(v as u8) }
            }
            bytes.extend(extra);
            let path = dir.path().join(name);
            std::fs::write(&path, bytes).unwrap();
            path
        };
        let data: Vec<u16> = (0..rows * cols).map(|i| (i * 37 % 4096) as u16).collect();
        let good = pgm("good.pgm", 4095, &data, &[]);
        let (r, top) = RowReader::open_pgm(&good, Some((rows, cols))).unwrap();
        assert_eq!(top, 4095);
        let mut out = vec![0u16; 5 * cols];
        r.read_u16(66, &mut out[..4 * cols]).unwrap();
        assert_eq!(out[..4 * cols], data[66 * cols..]);
        r.read_u16(0, &mut out).unwrap();
        assert_eq!(out, data[..5 * cols]);
        let bytes: Vec<u16> = data.iter().map(|&v| v % 251).collect();
        let small = pgm("eight.pgm", 250, &bytes, &[]);
        let (r, top) = RowReader::open_pgm(&small, None).unwrap();
        assert_eq!((top, r.size()), (250, (rows, cols)));
        let mut floats = vec![0.0f32; 2 * cols];
        r.read_f32(68, &mut floats).unwrap();
        assert_eq!(floats, bytes[68 * cols..].iter().map(|&v| f32::from(v)).collect::<Vec<_>>());
        let mut high = data.clone();
        high[68 * cols + 1] = 4096;
        let cut = &data[..data.len() - 1];
        for (path, size, want) in [
            (good.clone(), (cols, rows), "frame is 70 x 3, the capture's frames are 3 x 70"),
            (pgm("high.pgm", 4095, &high, &[]), (rows, cols), "pixel (68, 1) is 4096, above MAXVAL 4095"),
            (pgm("long.pgm", 4095, &data, &[0]), (rows, cols), "bytes after the 3 x 70 pixels the header promises"),
            (pgm("short.pgm", 4095, cut, &[]), (rows, cols), "truncated: 3 x 70 pixels promised"),
            (pgm("half.pgm", 4095, &data[..data.len() / 2], &[]), (rows, cols), "3 x 70 pixels need 420 bytes"),
        ] {
            let e = RowReader::open_pgm(&path, Some(size)).map(|_| ()).unwrap_err().to_string();
            assert!(e.starts_with(&path.display().to_string()) && e.contains(want), "{e}");
        }
    }
}

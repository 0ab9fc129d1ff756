//! A grey PNG raw frame read a few rows at a time ([`PngRows`]), so a paged decode holds
//! no PNG frame whole, as it holds no `.npy` or PGM frame ([`crate::io::row_reader`]).
//!
//! A PNG's rows are one compressed stream: a row can only be had by decoding every row
//! before it. So the reader keeps one decoder going down the file and hands out rows as
//! it passes them. Every pass of a decode goes down the frame (the paged cache asks for
//! its bands in order), so a pass decodes the file about once; a band asked for above the
//! decoder's place starts it again from the file's top (counted: [`PngRows::restarts`]).
//!
//! Only what can be read so is read so: 8- or 16-bit grey, not interlaced (Adam7 spreads
//! a row over seven passes), no transparency chunk. Any other PNG is read whole by the
//! image library (the frame file's whole read), which refuses what is not grey.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{Result, anyhow, ensure};

use crate::io::file_checks::{check_size, regular_file};

/// A grey 8- or 16-bit PNG, open for reading rows in order.
#[derive(Debug)]
pub struct PngRows {
    path: PathBuf,
    rows: usize,
    cols: usize,
    sixteen: bool,
    /// The file, kept open from the checks on, and the decoder going down it.
    stream: Mutex<Stream>,
    restarts: AtomicU64,
}

struct Stream {
    file: File,
    decoder: Option<(png::Reader<BufReader<File>>, usize)>,
}

impl std::fmt::Debug for Stream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Stream").field("next_row", &self.decoder.as_ref().map(|d| d.1)).finish()
    }
}

impl PngRows {
    /// Opens `path`: a PNG signature, nothing after its end chunk (IEND), its header (with
    /// `expect`, its size against the capture's) read now; no pixel yet. `None` for a valid
    /// PNG this reader does not read by rows (interlaced, another bit depth or colour, a
    /// transparency chunk): the caller reads it whole. The largest value it can hold (255
    /// or 65535) beside.
    ///
    /// # Errors
    /// The file and what is wrong with it.
    pub fn open(path: &Path, expect: Option<(usize, usize)>) -> Result<Option<(Self, u32)>> {
        let len = regular_file(path, u64::MAX, "")?;
        let end = png_end(path)?;
        ensure!(
            end == len,
            "{}: {} bytes after the PNG's end chunk (IEND) (the file is longer than its image)",
            path.display(),
            len.saturating_sub(end)
        );
        let file = File::open(path).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
        let reader = start(path, &file)?;
        let info = reader.info();
        check_size(path, (u64::from(info.height), u64::from(info.width)), expect)?;
        let grey = info.color_type == png::ColorType::Grayscale && info.trns.is_none() && !info.interlaced;
        let top = match info.bit_depth {
            png::BitDepth::Eight if grey => 255,
            png::BitDepth::Sixteen if grey => 65535,
            _ => return Ok(None),
        };
        let (rows, cols) = (info.height as usize, info.width as usize);
        let this = Self {
            path: path.to_path_buf(),
            rows,
            cols,
            sixteen: top > 255,
            stream: Mutex::new(Stream { file, decoder: Some((reader, 0)) }),
            restarts: AtomicU64::new(0),
        };
        Ok(Some((this, top)))
    }

    /// Decodes every row once, holding one, so a damaged stream (a bad checksum, data cut
    /// short) is refused now, before a decode that would stop on it at some band.
    ///
    /// # Errors
    /// The file and what is wrong with it.
    pub fn check_all(&self) -> Result<()> {
        let mut row = vec![0u16; self.cols];
        for r in 0..self.rows {
            self.read_rows(r, &mut row)?;
        }
        Ok(())
    }

    /// How often the decoder started again from the file's top for a row above its place.
    pub fn restarts(&self) -> u64 {
        self.restarts.load(Ordering::Relaxed)
    }

    /// `(rows, cols)`.
    pub fn size(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Rows `first..first + out.len() / cols` into `out`, as stored: decoded on from the
    /// decoder's place, or from the file's top for a row above it.
    ///
    /// # Errors
    /// Rows past the end, a damaged stream: the file and the rows.
    pub fn read_rows(&self, first: usize, out: &mut [u16]) -> Result<()> {
        let cols = self.cols.max(1);
        let n = out.len() / cols;
        let rows_text = || format!("rows {first}..{}", first + n);
        ensure!(
            out.len().is_multiple_of(cols) && first + n <= self.rows,
            "{}: {} of a {} x {} image",
            self.path.display(),
            rows_text(),
            self.rows,
            self.cols
        );
        let mut stream = self.stream.lock().map_err(|_| anyhow!("{}: a reader panicked", self.path.display()))?;
        let Stream { file, decoder } = &mut *stream;
        if decoder.as_ref().is_none_or(|(_, next)| *next > first) {
            *decoder = Some((start(&self.path, file)?, 0));
            self.restarts.fetch_add(1, Ordering::Relaxed);
        }
        let Some((reader, next)) = decoder.as_mut() else { return Err(anyhow!("{}: no decoder", self.path.display())) };
        let bad =
            |e: &dyn std::fmt::Display| anyhow!("{}: cannot decode image at {}: {e}", self.path.display(), rows_text());
        while *next < first + n {
            let row = reader.next_row().map_err(|e| bad(&e))?.ok_or_else(|| bad(&"the image data ends early"))?;
            if *next >= first {
                let at = &mut out[(*next - first) * cols..][..cols];
                if self.sixteen {
                    for (o, b) in at.iter_mut().zip(row.data().chunks_exact(2)) {
                        *o = u16::from_be_bytes([b[0], b[1]]);
                    }
                } else {
                    for (o, &b) in at.iter_mut().zip(row.data()) {
                        *o = u16::from(b);
                    }
                }
            }
            *next += 1;
        }
        Ok(())
    }
}

/// A decoder at the top of `file`'s image, its header read (the file's handle is shared:
/// one decoder at a time goes down it).
fn start(path: &Path, file: &File) -> Result<png::Reader<BufReader<File>>> {
    let bad = |e: &dyn std::fmt::Display| anyhow!("{}: cannot decode image: {e}", path.display());
    let mut file = file.try_clone().map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    file.seek(SeekFrom::Start(0)).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    png::Decoder::new(BufReader::new(file)).read_info().map_err(|e| bad(&e))
}

/// Where a PNG file's image ends: the byte after its IEND chunk, found by walking the
/// chunks' headers (length, type; each chunk is length + 12 bytes). Chunks are not read.
///
/// # Errors
/// A file that is not a PNG, or ends before IEND.
fn png_end(path: &Path) -> Result<u64> {
    let bad = |what: &str| anyhow!("{}: cannot decode image: {what}", path.display());
    let mut f = File::open(path).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    let mut signature = [0u8; 8];
    f.read_exact(&mut signature).map_err(|_| bad("not a PNG file"))?;
    ensure!(signature == *b"\x89PNG\r\n\x1a\n", bad("not a PNG file"));
    let mut at = 8u64;
    loop {
        let mut head = [0u8; 8];
        f.read_exact(&mut head).map_err(|_| bad("the file ends before its end chunk (IEND)"))?;
        let length = u64::from(u32::from_be_bytes([head[0], head[1], head[2], head[3]]));
        at += 12 + length;
        if &head[4..] == b"IEND" {
            return Ok(at);
        }
        f.seek(SeekFrom::Start(at)).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A grey PNG of `rows x cols` at `depth` (values as stored, big-endian at 16 bits).
    pub(crate) fn write_png(path: &Path, (rows, cols): (usize, usize), depth: png::BitDepth, values: &[u16]) {
        let file = std::io::BufWriter::new(File::create(path).unwrap());
        let mut enc = png::Encoder::new(file, cols as u32, rows as u32);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(depth);
        let bytes: Vec<u8> = match depth {
            png::BitDepth::Sixteen => values.iter().flat_map(|v| v.to_be_bytes()).collect(),
            png::BitDepth::Eight => values.iter().map(|&v| v as u8).collect(),
            _ => values.chunks(2).map(|p| (p[0] as u8) << 4 | p.get(1).map_or(0, |&v| v as u8)).collect(),
        };
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&bytes).unwrap();
        w.finish().unwrap();
    }

    /// 16- and 8-bit rows equal the values written, read in any order: bands asked for down
    /// the file decode it once (no restart), one above the decoder's place starts it again
    /// from the top and is still right; rows past the end are refused.
    #[test]
    fn rows_equal_the_values_written_in_any_order() {
        let dir = tempfile::tempdir().unwrap();
        let (rows, cols) = (70, 5);
        for (depth, top, modulo) in [(png::BitDepth::Sixteen, 65535, 65536), (png::BitDepth::Eight, 255, 256)] {
            let path = dir.path().join(format!("{top}.png"));
            let data: Vec<u16> = (0..rows * cols).map(|i| (i * 7919 % modulo) as u16).collect();
            write_png(&path, (rows, cols), depth, &data);
            let (r, got_top) = PngRows::open(&path, Some((rows, cols))).unwrap().unwrap();
            assert_eq!((got_top, r.size()), (top, (rows, cols)));
            let mut band = vec![0u16; 8 * cols];
            for first in (0..rows - 8).step_by(8) {
                r.read_rows(first, &mut band).unwrap();
                assert_eq!(band, data[first * cols..][..8 * cols], "{top}: rows from {first}");
            }
            assert_eq!(r.restarts(), 0, "{top}: down the file, one decoder");
            r.read_rows(3, &mut band).unwrap();
            assert_eq!(band, data[3 * cols..][..8 * cols], "{top}: rows from 3, again");
            assert_eq!(r.restarts(), 1);
            r.check_all().unwrap();
            let e = r.read_rows(66, &mut band).unwrap_err().to_string();
            assert!(e.contains(&format!("{top}.png")) && e.contains("rows 66..74"), "{e}");
        }
    }

    /// A damaged or odd PNG: a flipped byte in the image data is refused by the check of
    /// every row, naming the file; bytes after IEND and another size are refused at open;
    /// a 4-bit grey PNG is left to the whole read (`None`).
    #[test]
    fn a_faulty_png_is_refused_and_an_odd_one_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        let (rows, cols) = (40, 6);
        let data: Vec<u16> = (0..rows * cols).map(|i| (i * 331 % 65536) as u16).collect();
        let good = dir.path().join("good.png");
        write_png(&good, (rows, cols), png::BitDepth::Sixteen, &data);
        let bytes = std::fs::read(&good).unwrap();
        let idat = bytes.windows(4).position(|w| w == b"IDAT").unwrap();
        let mut flipped = bytes.clone();
        flipped[idat + 40] ^= 0x55;
        let damaged = dir.path().join("damaged.png");
        std::fs::write(&damaged, &flipped).unwrap();
        let (r, _) = PngRows::open(&damaged, Some((rows, cols))).unwrap().unwrap();
        let e = r.check_all().unwrap_err().to_string();
        assert!(e.starts_with(&damaged.display().to_string()) && e.contains("cannot decode image"), "{e}");
        let long = dir.path().join("long.png");
        std::fs::write(&long, [&bytes[..], &[0u8; 3]].concat()).unwrap();
        let e = PngRows::open(&long, None).map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("3 bytes after the PNG's end chunk"), "{e}");
        let e = PngRows::open(&good, Some((cols, rows))).map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("frame is 40 x 6, the capture's frames are 6 x 40"), "{e}");
        let four = dir.path().join("four.png");
        let nibbles: Vec<u16> = (0..rows * cols).map(|i| (i % 16) as u16).collect();
        write_png(&four, (rows, cols), png::BitDepth::Four, &nibbles);
        assert!(PngRows::open(&four, None).unwrap().is_none(), "4-bit: read whole");
    }
}

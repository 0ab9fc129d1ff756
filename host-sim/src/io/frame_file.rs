//! A raw frame's file: binary PGM, 8- or 16-bit grey PNG, or `.npy` (uint16, two axes),
//! read as the values stored (DN) with its size checked against the capture's before the
//! pixels are read, and written as `.npy`, `.pgm` or `.png`.

use std::path::Path;

use anyhow::{Context, Result, bail, ensure};

use crate::io::file_checks::regular_file;
use crate::io::lightfield::{read_npy_u16_2d, write_npy_u16_2d};
use crate::io::output::write_whole;
use crate::io::png_rows::PngRows;
use crate::io::row_reader::RowReader;

/// A raw frame as read from a file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameFile {
    /// Values as stored (DN), row-major.
    pub data: Vec<u16>,
    pub rows: usize,
    pub cols: usize,
    /// The largest value the file can hold: a PGM's MAXVAL, 255 or 65535 for PNG and `.npy`.
    pub top: u32,
}

/// Reads a 16-bit raw frame: binary PGM (P5), 8- or 16-bit grey PNG, or `.npy` (uint16, 2
/// axes). Values are DN as stored, whatever a PGM's MAXVAL says (image libraries rescale
/// a MAXVAL of 4095 to 65535 for display; a decoder must not). With `expect` (rows, cols),
/// a file whose header states another size is refused before its pixels are read.
///
/// # Errors
/// A message with the file and what is wrong.
pub fn read_frame(path: &Path, expect: Option<(usize, usize)>) -> Result<FrameFile> {
    regular_file(path, u64::MAX, "")?;
    match extension(path).as_str() {
        "npy" => {
            let (data, rows, cols) = read_npy_u16_2d(path, expect)?;
            Ok(FrameFile { data, rows, cols, top: u32::from(u16::MAX) })
        }
        "pgm" => read_pgm(path, expect),
        "png" => match PngRows::open(path, expect)? {
            Some((reader, top)) => {
                let (rows, cols) = reader.size();
                let mut data = vec![0u16; rows * cols];
                reader.read_rows(0, &mut data)?;
                Ok(FrameFile { data, rows, cols, top })
            }
            // Interlaced, another depth or colour: the image library reads it, and
            // refuses what is not grey.
            None => read_png_whole(path),
        },
        other => bail!("{}: unknown frame format {other:?} (use .pgm, .png or .npy)", path.display()),
    }
}

/// A PNG that [`PngRows`] does not read by rows (its end and its size against the
/// capture's were checked by [`PngRows::open`] from the same header), decoded whole by the
/// image library.
fn read_png_whole(path: &Path) -> Result<FrameFile> {
    let undecodable = || format!("{}: cannot decode image", path.display());
    let decoder = image::ImageReader::open(path)
        .and_then(image::ImageReader::with_guessed_format)
        .with_context(|| format!("cannot read {}", path.display()))?
        .into_decoder()
        .with_context(undecodable)?;
    let img = image::DynamicImage::from_decoder(decoder).with_context(undecodable)?;
    let color = img.color();
    let top = match color {
        image::ColorType::L8 => 255,
        image::ColorType::L16 => 65535,
        _ => bail!("{}: raw frame must be single-channel grey, found {color:?}", path.display()),
    };
    let g = img.into_luma16();
    let (w, h) = g.dimensions();
    let data = if top == 255 { g.into_raw().iter().map(|&x| x / 257).collect() } else { g.into_raw() };
    Ok(FrameFile { data, rows: h as usize, cols: w as usize, top })
}

/// A binary PGM, checked and read by [`RowReader::open_pgm`] (the paged reading's own
/// checks: one set), the samples as stored.
fn read_pgm(path: &Path, expect: Option<(usize, usize)>) -> Result<FrameFile> {
    let (reader, top) = RowReader::open_pgm(path, expect)?;
    let (rows, cols) = reader.size();
    let mut data = vec![0u16; rows * cols];
    reader.read_u16(0, &mut data)?;
    Ok(FrameFile { data, rows, cols, top })
}

/// Writes a 16-bit raw frame; the extension picks PGM, PNG or `.npy`.
///
/// # Errors
/// I/O and encoding errors, with the file.
pub fn write_frame(path: &Path, data: &[u16], rows: usize, cols: usize) -> Result<()> {
    match extension(path).as_str() {
        "npy" => write_npy_u16_2d(path, data, rows, cols),
        "pgm" => {
            // P5 with MAXVAL 65535, as docs/capture-format.md says: values as stored.
            use image::codecs::pnm::{GraymapHeader, PnmEncoder, SampleEncoding};
            ensure!(data.len() == rows * cols, "frame size does not match its data");
            let header = GraymapHeader {
                encoding: SampleEncoding::Binary,
                height: rows as u32,
                width: cols as u32,
                maxwhite: u32::from(u16::MAX),
            };
            let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_ne_bytes()).collect();
            write_whole(path, |out| {
                PnmEncoder::new(out).with_header(header.into()).encode(
                    &bytes[..],
                    cols as u32,
                    rows as u32,
                    image::ExtendedColorType::L16,
                )?;
                Ok(())
            })
        }
        "png" => {
            use image::ImageEncoder;
            ensure!(data.len() == rows * cols, "frame size does not match its data");
            let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_ne_bytes()).collect();
            write_whole(path, |out| {
                image::codecs::png::PngEncoder::new(out).write_image(
                    &bytes,
                    cols as u32,
                    rows as u32,
                    image::ExtendedColorType::L16,
                )?;
                Ok(())
            })
        }
        other => bail!("{}: unknown frame format {other:?} (use .pgm, .png or .npy)", path.display()),
    }
}

/// A path's extension, lower case (`""` without one).
pub(crate) fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Frame file names for `k` snapshots with extension `ext`.
pub fn frame_names(k: usize, ext: &str) -> Vec<String> {
    (0..k).map(|j| format!("snapshot_{j}.{ext}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::png_rows::tests::write_png;

    /// A PNG read whole: 16- and 8-bit grey through the row reader, the values as written
    /// and the top their depth holds; a 4-bit one by the image library, every pixel there.
    #[test]
    fn a_png_is_read_whole_as_written() {
        let dir = tempfile::tempdir().unwrap();
        let (rows, cols) = (33, 8); // even: the helper packs 4-bit pixels two a byte across rows
        for (depth, top) in [(png::BitDepth::Sixteen, 65535u32), (png::BitDepth::Eight, 255)] {
            let data: Vec<u16> = (0..rows * cols).map(|i| (i * 7919 % (top as usize + 1)) as u16).collect();
            let path = dir.path().join(format!("{top}.png"));
            write_png(&path, (rows, cols), depth, &data);
            let whole = read_frame(&path, Some((rows, cols))).unwrap();
            assert_eq!((whole.data, whole.top, whole.rows, whole.cols), (data, top, rows, cols), "{top}");
        }
        let four = dir.path().join("four.png");
        let nibbles: Vec<u16> = (0..rows * cols).map(|i| (i % 16) as u16).collect();
        write_png(&four, (rows, cols), png::BitDepth::Four, &nibbles);
        let whole = read_frame(&four, Some((rows, cols))).unwrap();
        assert_eq!((whole.rows, whole.cols, whole.data.len(), whole.top), (rows, cols, rows * cols, 255));
    }
}

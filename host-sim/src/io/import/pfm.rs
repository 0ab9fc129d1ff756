//! Portable float maps (`.pfm`), the format of the HCI benchmark's disparity maps.
//!
//! A text header, `Pf` (one channel) or `PF` (three), the width and height, and a scale
//! whose sign gives the byte order (negative: little-endian); then `f32` values, rows from
//! the bottom of the image up. Sizes are checked against the file before anything is
//! allocated; a three-channel map is read as its first channel.

use std::io::Read;
use std::path::Path;

use anyhow::{Context, Result, bail, ensure};

use super::Plane;

/// The largest side a map may claim.
const MAX_SIDE: usize = 1 << 16;

/// Reads a `.pfm` as a single-channel plane, top row first.
pub fn read_pfm(path: &Path) -> Result<Plane> {
    let meta = std::fs::metadata(path).with_context(|| format!("{}: cannot read", path.display()))?;
    ensure!(meta.is_file(), "{}: not a regular file", path.display());
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(4 * (MAX_SIDE * MAX_SIDE) as u64 * 3 + 256).read_to_end(&mut bytes))
        .with_context(|| format!("{}: cannot read", path.display()))?;
    parse_pfm(&bytes).with_context(|| format!("{}: not a valid PFM", path.display()))
}

/// Parses the bytes of a `.pfm`.
pub fn parse_pfm(bytes: &[u8]) -> Result<Plane> {
    let mut pos = 0usize;
    let mut token = || -> Result<&[u8]> {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() && pos - start < 32 {
            pos += 1;
        }
        ensure!(pos > start, "header ends early (at byte {start})");
        Ok(&bytes[start..pos])
    };
    let channels = match token()? {
        b"Pf" => 1,
        b"PF" => 3,
        other => bail!("magic {:?}: expected Pf or PF", String::from_utf8_lossy(other)),
    };
    let mut number = |what: &str| -> Result<String> {
        let t = token()?;
        String::from_utf8(t.to_vec()).map_err(|_| anyhow::anyhow!("{what} is not text"))
    };
    let w = number("width")?;
    let h = number("height")?;
    let s = number("scale")?;
    let cols: usize = w.parse().map_err(|_| anyhow::anyhow!("width {w:?} is not a whole number"))?;
    let rows: usize = h.parse().map_err(|_| anyhow::anyhow!("height {h:?} is not a whole number"))?;
    let scale: f32 = s.parse().map_err(|_| anyhow::anyhow!("scale {s:?} is not a number"))?;
    ensure!(scale.is_finite() && scale != 0.0, "scale {scale} must be finite and not 0");
    ensure!(
        (1..=MAX_SIDE).contains(&cols) && (1..=MAX_SIDE).contains(&rows),
        "size {cols} x {rows} is not within 1..={MAX_SIDE} a side"
    );
    // Exactly one whitespace byte ends the header.
    let body = pos + 1;
    let need = rows * cols * channels * 4;
    ensure!(
        bytes.len() >= body && bytes.len() - body == need,
        "{cols} x {rows} x {channels} floats need {need} bytes after the header; the file has {}",
        bytes.len().saturating_sub(body)
    );
    let little = scale < 0.0;
    let mut data = vec![0.0f32; rows * cols];
    for r in 0..rows {
        // PFM rows run from the bottom up.
        let src_row = rows - 1 - r;
        for c in 0..cols {
            let at = body + ((src_row * cols + c) * channels) * 4;
            let b = [bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]];
            let v = if little { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) };
            ensure!(v.is_finite(), "value at row {r}, column {c} (top first) is {v}");
            data[r * cols + c] = v;
        }
    }
    Ok(Plane { rows, cols, channels: 1, data })
}

/// A single-channel plane as `.pfm` bytes (little-endian, bottom row first).
pub fn pfm_bytes(plane: &Plane) -> Vec<u8> {
    let mut out = format!("Pf\n{} {}\n-1.0\n", plane.cols, plane.rows).into_bytes();
    for r in (0..plane.rows).rev() {
        for c in 0..plane.cols {
            out.extend_from_slice(&plane.data[(r * plane.cols + c) * plane.channels].to_le_bytes());
        }
    }
    out
}

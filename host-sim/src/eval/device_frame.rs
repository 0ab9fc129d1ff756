//! The device's frame figure: projected seconds for a camera-sized frame on the device,
//! from instruction counts on the emulated core.
//!
//! `scripts/budgets.sh` counts the instructions of a patch solve on qemu's Cortex-M7 (`mps2-an500`) and
//! writes, per kind of decode, how many patch solves a 100 x 100-lenslet frame takes, the
//! instructions of one solve and the clock they are projected at
//! (`target/device-frame.csv`). `slf bench --device FILE` puts that table beside the host's
//! frame figure (`bench.md`), so one page shows both: the host's seconds measured, the
//! device's projected from counts (one instruction a cycle; a Cortex-M7 issues up to two).
//!
//! The file is checked before anything is kept: a regular file (`io::file_checks::regular_file`)
//! of at most [`MAX_BYTES`], at most [`MAX_ROWS`] rows,
//! every number finite and positive, each fault named with its line.

use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::io::file_checks::regular_file;

/// The largest device-frame file read: a few rows of text.
pub const MAX_BYTES: u64 = 64 * 1024;
/// The most rows kept.
pub const MAX_ROWS: usize = 64;

/// The header `scripts/budgets.sh` writes.
pub const HEADER: [&str; 4] = ["decode", "patch_solves", "instructions_per_solve", "clock_mhz"];

/// One kind of decode's projected frame on the device.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceFrame {
    /// What is decoded, as a reader names it (e.g. "default: screened ensemble, stride 3").
    pub decode: String,
    /// Patch solves the frame takes.
    pub patch_solves: f64,
    /// Instructions of one patch solve, counted on the emulated core.
    pub instructions_per_solve: f64,
    /// The clock the seconds are projected at, MHz, one instruction a cycle.
    pub clock_mhz: f64,
}

impl DeviceFrame {
    /// Projected seconds for the frame.
    pub fn seconds(&self) -> f64 {
        self.patch_solves * self.instructions_per_solve / (self.clock_mhz * 1e6)
    }
}

/// Reads the device-frame table at `path` (the CSV `scripts/budgets.sh` writes).
///
/// # Errors
/// A file that cannot be read, is not a regular file or is larger than [`MAX_BYTES`], lacks the [`HEADER`], or has
/// a row that is not a name and three finite positive numbers (the line is named), or
/// more than [`MAX_ROWS`] rows.
pub fn read(path: &Path) -> Result<Vec<DeviceFrame>> {
    regular_file(path, MAX_BYTES, "a device-frame table holds")?;
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse(&text).with_context(|| format!("{}", path.display()))
}

/// [`read`] on the file's text.
///
/// # Errors
/// As [`read`].
pub fn parse(text: &str) -> Result<Vec<DeviceFrame>> {
    let mut r = csv::ReaderBuilder::new().has_headers(true).from_reader(text.as_bytes());
    let header: Vec<String> = r.headers().context("header")?.iter().map(str::to_owned).collect();
    if header != HEADER {
        bail!("line 1: header {header:?}, expected {HEADER:?}");
    }
    let mut frames = Vec::new();
    for (i, row) in r.records().enumerate() {
        let line = i + 2;
        let row = row.with_context(|| format!("line {line}"))?;
        if frames.len() == MAX_ROWS {
            bail!("line {line}: more than {MAX_ROWS} rows");
        }
        if row.len() != HEADER.len() {
            bail!("line {line}: {} fields, expected {}", row.len(), HEADER.len());
        }
        let number = |j: usize| -> Result<f64> {
            let x: f64 = row[j].trim().parse().with_context(|| format!("line {line}: {} {:?}", HEADER[j], &row[j]))?;
            if !(x.is_finite() && x > 0.0) {
                bail!("line {line}: {} is {x}, expected a finite positive number", HEADER[j]);
            }
            Ok(x)
        };
        frames.push(DeviceFrame {
            decode: row[0].trim().to_owned(),
            patch_solves: number(1)?,
            instructions_per_solve: number(2)?,
            clock_mhz: number(3)?,
        });
    }
    Ok(frames)
}

/// The table `slf bench` appends to `bench.md`.
pub fn markdown(frames: &[DeviceFrame]) -> String {
    let mut md = String::from(
        "\n## The device's frame figure\n\nA 100 x 100-lenslet frame (5 x 5 views) on the device, projected from instruction \
         counts on qemu's Cortex-M7 `mps2-an500` (`scripts/budgets.sh`) at one instruction a cycle:\n\n\
         | decode | patch solves | instructions a solve | clock, MHz | seconds a frame |\n| --- | --- | --- | --- | --- |\n",
    );
    for f in frames {
        md += &format!(
            "| {} | {:.0} | {:.1} M | {:.0} | {:.0} |\n",
            f.decode,
            f.patch_solves,
            f.instructions_per_solve / 1e6,
            f.clock_mhz,
            f.seconds()
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "decode,patch_solves,instructions_per_solve,clock_mhz\n\
                        \"default: screened ensemble, stride 3\",6080,93587147,480\n\
                        DCT on the disjoint grid,1600,52521593,480\n";

    #[test]
    fn seconds_are_solves_times_instructions_over_the_clock() {
        let frames = parse(GOOD).unwrap();
        assert_eq!(frames.len(), 2);
        assert_eq!(frames[0].decode, "default: screened ensemble, stride 3");
        // 6,080 x 93,587,147 / 480e6, worked by hand: 1,185.4 s.
        assert!((frames[0].seconds() - 1185.44).abs() < 0.01, "{}", frames[0].seconds());
        assert!((frames[1].seconds() - 175.07).abs() < 0.01, "{}", frames[1].seconds());
        let md = markdown(&frames);
        assert!(md.contains("| default: screened ensemble, stride 3 | 6080 | 93.6 M | 480 | 1185 |"), "{md}");
        assert!(md.contains("| DCT on the disjoint grid | 1600 | 52.5 M | 480 | 175 |"), "{md}");
    }

    #[test]
    fn bad_tables_are_refused_with_their_line() {
        for (text, says) in [
            ("name,solves\nx,1\n", "line 1: header"),
            ("decode,patch_solves,instructions_per_solve,clock_mhz\nx,1,2\n", "line 2"),
            (
                "decode,patch_solves,instructions_per_solve,clock_mhz\nx,1,2,3\ny,nan,2,3\n",
                "line 3: patch_solves is NaN",
            ),
            (
                "decode,patch_solves,instructions_per_solve,clock_mhz\nx,1,-2,3\n",
                "line 2: instructions_per_solve is -2",
            ),
            ("decode,patch_solves,instructions_per_solve,clock_mhz\nx,1,2,fast\n", "line 2: clock_mhz \"fast\""),
        ] {
            let e = format!("{:#}", parse(text).unwrap_err());
            assert!(e.contains(says), "{text:?}: {e}");
        }
        let many =
            String::from("decode,patch_solves,instructions_per_solve,clock_mhz\n") + &"x,1,2,3\n".repeat(MAX_ROWS + 1);
        assert!(format!("{:#}", parse(&many).unwrap_err()).contains("more than 64 rows"));
        let dir = tempfile::tempdir().unwrap();
        let big = dir.path().join("big.csv");
        std::fs::write(&big, vec![b'x'; MAX_BYTES as usize + 1]).unwrap();
        assert!(format!("{:#}", read(&big).unwrap_err()).contains("more than the 65536 a device-frame table holds"));
    }
}

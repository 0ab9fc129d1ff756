//! Captures on disk: a folder with one raw frame per snapshot and a `capture.json`.
//!
//! The format is documented in `docs/capture-format.md`; another tool can write a capture
//! that `slf decode` reads. Loading checks everything and says what is wrong and where.

use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use serde::{Deserialize, Serialize};
use slf_firmware::{
    BandTile, DecoderConfig, DefectList, LensletSize, Mask, MaskFamily, Pixel, RawFormat, RawFrame, SensorGeometry,
    Sl0Config, TileDecoder,
};

use crate::lightfield::{read_npy_u16_2d, write_npy_u16_2d};

/// The description file's name inside a capture folder.
pub const DESCRIPTION: &str = "capture.json";
/// The `format` field's value.
pub const FORMAT: &str = "slf-capture";
/// The `version` field's value.
pub const VERSION: u32 = 1;

/// The mask, by family and seed, or (pixel and lenslet) as an explicit periodic tile.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "lowercase")]
pub enum MaskDescription {
    /// Band per sensor pixel and snapshot.
    Pixel(MaskSource),
    /// Band per lenslet and snapshot.
    Lenslet(MaskSource),
    /// The paper's: band per block of `block` lenslets and snapshot.
    Kronecker { snapshots: u8, seed: u64, block: [u8; 2] },
}

impl MaskDescription {
    /// A seeded mask of `family` with `snapshots` snapshots; a kronecker mask's block is the
    /// decoder's patch (5 x 5 lenslets).
    pub fn seeded(family: MaskFamily, seed: u64, snapshots: u8) -> Self {
        let src = MaskSource { snapshots: Some(snapshots), seed: Some(seed), tile: None };
        match family {
            MaskFamily::Pixel => Self::Pixel(src),
            MaskFamily::Lenslet => Self::Lenslet(src),
            MaskFamily::Kronecker => Self::Kronecker { snapshots, seed, block: [5, 5] },
        }
    }
}

/// A seed and snapshot count, or a tile `tile[snapshot][row][col]` of band indices.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaskSource {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub snapshots: Option<u8>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tile: Option<Vec<Vec<Vec<u8>>>>,
}

/// Sensor noise as simulated (informational; a decoder may use it for the noise floor).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseDescription {
    /// Electrons collected at the white level (shot noise).
    pub full_well_electrons: f32,
    /// Read noise standard deviation in DN.
    pub read_noise_dn: f32,
}

/// `capture.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaptureDescription {
    pub format: String,
    pub version: u32,
    /// Lenslet rows and columns `[S, T]`.
    pub lenslets: [usize; 2],
    /// Pixels (views) under a lenslet `[U, V]`; the frame is `S*U x T*V`.
    pub views: [usize; 2],
    /// Band centres in nm, one per filter type.
    pub bands_nm: Vec<f32>,
    pub mask: MaskDescription,
    /// Frame files, one per snapshot, in snapshot order, relative to the folder.
    pub frames: Vec<String>,
    /// Sensor bit depth (informational).
    pub bits: u8,
    /// Raw value of no light.
    pub black_level: f32,
    /// Raw value of a white surface in the brightest band.
    pub white_level: f32,
    /// Raw values at or above this are saturated and not used.
    pub saturation_level: f32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<NoiseDescription>,
    /// `[row, col]` of pixels that are not measurements.
    #[serde(default)]
    pub defective_pixels: Vec<[u32; 2]>,
}

/// A loaded capture: description, frames and the checked pieces the decoder needs.
#[derive(Clone, Debug)]
pub struct Capture {
    pub description: CaptureDescription,
    /// One raw frame per snapshot, row-major.
    pub frames: Vec<Vec<u16>>,
    /// Flattened tile bands (`[snapshot][row][col]`) when the mask is a tile.
    tile_bands: Vec<u8>,
    /// Defective pixels, sorted.
    defects: Vec<Pixel>,
}

impl Capture {
    /// Builds a capture from a description and frames, checking them against each other.
    ///
    /// # Errors
    /// A message naming the field that is wrong.
    pub fn new(description: CaptureDescription, frames: Vec<Vec<u16>>) -> Result<Self> {
        let d = &description;
        ensure!(d.format == FORMAT, "format is {:?}, expected {FORMAT:?}", d.format);
        ensure!(d.version == VERSION, "version {} is not supported (this slf reads {VERSION})", d.version);
        ensure!(
            d.lenslets.iter().all(|&x| (1..=u16::MAX as usize).contains(&x)),
            "lenslets {:?} out of range",
            d.lenslets
        );
        ensure!(d.views.iter().all(|&x| (1..=255).contains(&x)), "views {:?} out of range 1..=255", d.views);
        ensure!((1..=32).contains(&d.bands_nm.len()), "bands_nm has {} entries, expected 1..=32", d.bands_nm.len());
        ensure!(
            d.black_level.is_finite() && d.white_level > d.black_level && d.saturation_level > d.black_level,
            "levels: need black_level < white_level and black_level < saturation_level"
        );
        ensure!(frames.len() == d.frames.len(), "{} frames for {} names", frames.len(), d.frames.len());
        let (rows, cols) = (d.lenslets[0] * d.views[0], d.lenslets[1] * d.views[1]);
        for (i, f) in frames.iter().enumerate() {
            ensure!(
                f.len() == rows * cols,
                "frame {i} ({}) holds {} pixels, expected {rows} x {cols}",
                d.frames[i],
                f.len()
            );
        }
        let tile_bands = match &d.mask {
            MaskDescription::Pixel(MaskSource { tile: Some(t), .. })
            | MaskDescription::Lenslet(MaskSource { tile: Some(t), .. }) => {
                ensure!(!t.is_empty() && !t[0].is_empty() && !t[0][0].is_empty(), "mask.tile is empty");
                let (r, c) = (t[0].len(), t[0][0].len());
                ensure!(
                    t.iter().all(|s| s.len() == r && s.iter().all(|row| row.len() == c)),
                    "mask.tile: every snapshot must be {r} rows of {c} columns"
                );
                t.iter().flatten().flatten().copied().collect()
            }
            _ => Vec::new(),
        };
        let mut defects = Vec::with_capacity(d.defective_pixels.len());
        for &[r, c] in &d.defective_pixels {
            ensure!(
                (r as usize) < rows && (c as usize) < cols,
                "defective pixel [{r}, {c}] outside the {rows} x {cols} frame"
            );
            defects.push(Pixel { row: r as u16, col: c as u16 });
        }
        defects.sort();
        defects.dedup();
        let capture = Self { description, frames, tile_bands, defects };
        let mask = capture.mask()?;
        ensure!(
            mask.snapshots() == capture.frames.len(),
            "mask has {} snapshots, capture has {} frames",
            mask.snapshots(),
            capture.frames.len()
        );
        Ok(capture)
    }

    /// Sensor geometry.
    pub fn sensor(&self) -> SensorGeometry {
        let d = &self.description;
        SensorGeometry {
            lenslets: (d.lenslets[0] as u16, d.lenslets[1] as u16),
            lenslet: LensletSize { rows: d.views[0] as u8, cols: d.views[1] as u8 },
        }
    }

    /// Frame size `(rows, cols)`.
    pub fn frame_size(&self) -> (usize, usize) {
        self.sensor().frame_size()
    }

    /// The mask, built by the firmware's own code.
    ///
    /// # Errors
    /// What the firmware rejects (counts, tile contents), or a missing seed or tile.
    pub fn mask(&self) -> Result<Mask<'_>> {
        let d = &self.description;
        let bands = d.bands_nm.len() as u8;
        let lenslet = self.sensor().lenslet;
        let m = match &d.mask {
            MaskDescription::Kronecker { snapshots, seed, block } => {
                Mask::kronecker(*seed, *snapshots, bands, lenslet, (block[0], block[1]))
            }
            MaskDescription::Pixel(src) | MaskDescription::Lenslet(src) => {
                let pixel = matches!(d.mask, MaskDescription::Pixel(_));
                match (&src.tile, src.seed, src.snapshots) {
                    (Some(t), None, snapshots) => {
                        let k = t.len() as u8;
                        if let Some(s) = snapshots {
                            ensure!(s == k, "mask.snapshots is {s} but mask.tile has {k} snapshots");
                        }
                        let tile = BandTile::new(t[0].len() as u16, t[0][0].len() as u16, k, bands, &self.tile_bands)
                            .map_err(|e| anyhow::anyhow!("mask.tile: {e}"))?;
                        if pixel {
                            Mask::pixel_tile(tile, bands, lenslet)
                        } else {
                            Mask::lenslet_tile(tile, bands, lenslet)
                        }
                    }
                    (None, Some(seed), Some(k)) => {
                        if pixel {
                            Mask::pixel(seed, k, bands, lenslet)
                        } else {
                            Mask::lenslet(seed, k, bands, lenslet)
                        }
                    }
                    _ => bail!("mask: give either `seed` and `snapshots`, or `tile`"),
                }
            }
        };
        m.map_err(|e| anyhow::anyhow!("mask: {e}"))
    }

    /// How raw values map to measurements.
    pub fn raw_format(&self) -> RawFormat {
        let d = &self.description;
        RawFormat { black: d.black_level, white: d.white_level, max_valid: d.saturation_level - 0.5 }
    }

    /// The firmware's tile decoder for this capture (the paper's 5 x 5 x 4 x 4 x 13 patch).
    ///
    /// # Errors
    /// A mask or geometry the decoder does not take, with the reason.
    pub fn decoder(&self, sl0: Sl0Config) -> Result<TileDecoder<'_, 5, 5, 4, 4, 13, 5200>> {
        let config = DecoderConfig {
            sensor: self.sensor(),
            mask: self.mask()?,
            raw: self.raw_format(),
            defects: self.defects(),
            sl0,
        };
        TileDecoder::new(config).map_err(|e| anyhow::anyhow!("decoder: {e}"))
    }

    /// The frames as the decoder reads them.
    ///
    /// # Errors
    /// A frame whose size differs from the description's (checked in `new`, so not expected).
    pub fn raw_frames(&self) -> Result<Vec<RawFrame<'_, u16>>> {
        let (rows, cols) = self.frame_size();
        self.frames.iter().map(|f| RawFrame::new(f, rows, cols).map_err(|e| anyhow::anyhow!("{e}"))).collect()
    }

    /// The defect list for the decoder.
    pub fn defects(&self) -> DefectList<'_> {
        // Sorted and deduplicated in `new`, so this cannot fail.
        DefectList::new(&self.defects).unwrap_or_default()
    }

    /// Loads a capture folder.
    ///
    /// # Errors
    /// A message with the file and what is wrong in it.
    pub fn load(dir: &Path) -> Result<Self> {
        let desc_path = dir.join(DESCRIPTION);
        let text = fs::read_to_string(&desc_path).with_context(|| format!("cannot read {}", desc_path.display()))?;
        let description: CaptureDescription = serde_json::from_str(&text)
            .with_context(|| format!("{}: invalid capture description", desc_path.display()))?;
        let (rows, cols) =
            (description.lenslets[0] * description.views[0], description.lenslets[1] * description.views[1]);
        let mut frames = Vec::with_capacity(description.frames.len());
        for name in &description.frames {
            let path = dir.join(name);
            let (data, r, c) = read_frame(&path)?;
            ensure!(
                (r, c) == (rows, cols),
                "{}: frame is {r} x {c}, the description implies {rows} x {cols}",
                path.display()
            );
            frames.push(data);
        }
        Self::new(description, frames).with_context(|| format!("{}: inconsistent capture", desc_path.display()))
    }

    /// Writes the capture folder: `capture.json` and the frames under their names
    /// (the extension picks the format: `.pgm`, `.png` or `.npy`).
    ///
    /// # Errors
    /// I/O and encoding errors, with the file.
    pub fn save(&self, dir: &Path) -> Result<()> {
        fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let (rows, cols) = self.frame_size();
        for (name, data) in self.description.frames.iter().zip(&self.frames) {
            write_frame(&dir.join(name), data, rows, cols)?;
        }
        let path = dir.join(DESCRIPTION);
        let text = serde_json::to_string_pretty(&self.description)?;
        fs::write(&path, text + "\n").with_context(|| format!("cannot write {}", path.display()))
    }
}

/// Reads a 16-bit raw frame: PGM or PNG (16-bit grey) or `.npy` (uint16, 2 axes).
///
/// # Errors
/// A message with the file and what is wrong.
pub fn read_frame(path: &Path) -> Result<(Vec<u16>, usize, usize)> {
    match extension(path).as_str() {
        "npy" => read_npy_u16_2d(path),
        "pgm" | "png" => {
            let img = image::open(path).with_context(|| format!("{}: cannot decode image", path.display()))?;
            let color = img.color();
            ensure!(
                matches!(color, image::ColorType::L16 | image::ColorType::L8),
                "{}: raw frame must be single-channel grey, found {color:?}",
                path.display()
            );
            let g = img.into_luma16();
            let (w, h) = g.dimensions();
            let data = if color == image::ColorType::L8 {
                g.into_raw().iter().map(|&x| x / 257).collect()
            } else {
                g.into_raw()
            };
            Ok((data, h as usize, w as usize))
        }
        other => bail!("{}: unknown frame format {other:?} (use .pgm, .png or .npy)", path.display()),
    }
}

/// Writes a 16-bit raw frame; the extension picks PGM, PNG or `.npy`.
///
/// # Errors
/// I/O and encoding errors, with the file.
pub fn write_frame(path: &Path, data: &[u16], rows: usize, cols: usize) -> Result<()> {
    match extension(path).as_str() {
        "npy" => write_npy_u16_2d(path, data, rows, cols).with_context(|| format!("cannot write {}", path.display())),
        "pgm" | "png" => {
            let img =
                image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(cols as u32, rows as u32, data.to_vec())
                    .context("frame size does not match its data")?;
            img.save(path).with_context(|| format!("cannot write {}", path.display()))
        }
        other => bail!("{}: unknown frame format {other:?} (use .pgm, .png or .npy)", path.display()),
    }
}

fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Frame file names for `k` snapshots with extension `ext`.
pub fn frame_names(k: usize, ext: &str) -> Vec<String> {
    (0..k).map(|j| format!("snapshot_{j}.{ext}")).collect()
}

/// The folder path's description file.
pub fn description_path(dir: &Path) -> PathBuf {
    dir.join(DESCRIPTION)
}

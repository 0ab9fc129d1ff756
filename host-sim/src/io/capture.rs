//! Captures on disk: a folder with one raw frame per snapshot and a `capture.json`.
//!
//! The format is documented in `docs/capture-format.md`; another tool can write a capture
//! that `slf decode` reads. Loading checks everything and says what is wrong and where.

use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail, ensure};
use serde::{Deserialize, Serialize};
use slf_firmware::{
    BandTile, DecoderConfig, DefectList, LensletSize, Mask, MaskFamily, Pixel, RawFormat, SensorGeometry, Sl0Config,
    TileDecoder,
};

use crate::io::file_checks::read_small_file;
use crate::io::folder::{FileRecord, Kind, WholeFolder, record, verify};
use crate::io::frame_file::{extension, write_frame};
use crate::io::frames::{Frames, SensorFrame, frame_path, inside, is_frame_name};
use crate::io::grid::GridDescription;
use crate::io::map::Map;
use crate::io::message::one_line;
use crate::io::output::write_bytes;
use crate::io::sensor::SensorDescription;

/// The largest `capture.json` read (a long defect list fits many times over).
pub const MAX_DESCRIPTION: u64 = 64 << 20;

use crate::io::patch::HostDecoder;
use slf_firmware::shape::MAX_BANDS;

/// The description file's name inside a capture folder.
pub const DESCRIPTION: &str = "capture.json";
/// The `format` field's value.
pub const FORMAT: &str = "slf-capture";
/// The `version` field's value: 1, or 2 for a capture that records its simulated sensor
/// (`simulated_sensor`). Both are read; a capture of the ideal sensor is written as 1, as
/// before version 2.
pub const VERSION: u32 = 1;
/// The version of a capture with a `simulated_sensor`.
pub const VERSION_SENSOR: u32 = 2;

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

    /// The family.
    pub fn family(&self) -> MaskFamily {
        match self {
            Self::Pixel(_) => MaskFamily::Pixel,
            Self::Lenslet(_) => MaskFamily::Lenslet,
            Self::Kronecker { .. } => MaskFamily::Kronecker,
        }
    }

    /// The family's name, as `capture.json` writes it.
    pub fn family_name(&self) -> &'static str {
        match self {
            Self::Pixel(_) => "pixel",
            Self::Lenslet(_) => "lenslet",
            Self::Kronecker { .. } => "kronecker",
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

/// Sensor noise as simulated: the decoder's noise model by default ([`Capture::noise_model`]).
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
    /// The sensor a simulated capture was made with (version 2): what a calibration should
    /// recover. The decoder never reads it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulated_sensor: Option<SensorDescription>,
    /// The light the capture was taken under (version 2): a scene (the default, left out),
    /// or one of the calibration captures `slf calibrate` reads.
    #[serde(default, skip_serializing_if = "Light::is_scene")]
    pub light: Light,
    /// Where the lenslet array sits on the sensor (version 2, [`crate::io::grid`]): the
    /// frames are then its sensor's size, not `S*U x T*V`. Absent: the aligned grid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lenslet_grid: Option<GridDescription>,
    /// Each frame's size and CRC-32 as written ([`crate::io::folder`]), checked on load; a
    /// loaded capture's description holds none (they describe the files, not the capture).
    /// Absent in folders written before they were (loaded with a note).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub files: Option<Vec<FileRecord>>,
}

/// What a capture looked at: a scene, or a calibration target.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Light {
    /// A scene to decode.
    #[default]
    Scene,
    /// No light (the lens capped): each pixel's dark level.
    Dark,
    /// A uniform white target under light of equal energy in every band, `level` times
    /// white: each pixel's gain and its view's vignetting.
    Flat { level: f32 },
    /// A uniform white target under light of band `band` only, `level` times white: every
    /// filter's response to that band.
    Band { band: u8, level: f32 },
}

impl Light {
    /// Whether it is a scene's (the field is then left out of `capture.json`).
    pub fn is_scene(&self) -> bool {
        *self == Light::Scene
    }
}

/// The shortest band centre a capture may state, nm.
pub const MIN_NM: f32 = 200.0;
/// The longest band centre a capture may state, nm.
pub const MAX_NM: f32 = 2500.0;

/// A loaded capture: description, frames and the checked pieces the decoder needs.
#[derive(Clone, Debug)]
pub struct Capture {
    pub description: CaptureDescription,
    /// One raw frame per snapshot, row-major: held, or read from the files a band at a
    /// time ([`Capture::load`] of `.npy` frames).
    pub frames: Frames,
    /// Flattened tile bands (`[snapshot][row][col]`) when the mask is a tile.
    tile_bands: Vec<u8>,
    /// Defective pixels, sorted.
    defects: Vec<Pixel>,
    /// The `capture.json` it was loaded from, if any.
    source: Option<PathBuf>,
    /// The per-pixel flat its frames were divided by (corrected by a calibration): a
    /// value's noise is the raw value's over it.
    flat: Option<Map>,
}

impl Capture {
    /// Builds a capture from a description and frames, checking them against each other.
    ///
    /// # Errors
    /// A message naming the field that is wrong.
    pub fn new(description: CaptureDescription, frames: Vec<Vec<u16>>) -> Result<Self> {
        Self::with_frames(description, Frames::Held(frames))
    }

    /// As [`Self::new`], with frames held or paged (a paged frame's size was checked when
    /// its file was opened).
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn with_frames(description: CaptureDescription, frames: Frames) -> Result<Self> {
        let d = &description;
        let (rows, cols) = d.frame_size()?;
        ensure!(frames.len() == d.frames.len(), "{} frames for {} names", frames.len(), d.frames.len());
        // The names are where `save` writes: inside the folder, each once, a known format.
        for (i, name) in d.frames.iter().enumerate() {
            frame_path(Path::new(""), name).map_err(|e| anyhow!("frames[{i}]: {}", one_line(&e)))?;
            ensure!(
                matches!(extension(Path::new(name)).as_str(), "pgm" | "png" | "npy"),
                "frames[{i}]: {name:?} is not a .pgm, .png or .npy file"
            );
            ensure!(!d.frames[..i].contains(name), "frames[{i}]: {name:?} is named twice (one file per snapshot)");
        }
        for (i, f) in frames.in_memory().iter().enumerate() {
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
                ensure!(t.len() <= MAX_BANDS, "mask.tile has {} snapshots, at most {}", t.len(), MAX_BANDS);
                ensure!(
                    r <= usize::from(u16::MAX) && c <= usize::from(u16::MAX),
                    "mask.tile is {r} x {c} cells, at most {} x {}",
                    u16::MAX,
                    u16::MAX
                );
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
        if let Some(n) = d.noise {
            // Noise above the signal's whole range is not a camera: its projection ball
            // would hold any image (a read noise of 1e30 decoded at 7 dB, without a word).
            let range = d.white_level - d.black_level;
            ensure!(
                n.read_noise_dn.is_finite() && n.read_noise_dn >= 0.0 && n.read_noise_dn < range,
                "noise.read_noise_dn {}: must be finite, at or above 0 and below the signal range \
                 (white_level - black_level = {range} DN)",
                n.read_noise_dn
            );
            ensure!(
                n.full_well_electrons.is_finite() && n.full_well_electrons >= 1.0,
                "noise.full_well_electrons {}: must be finite and at least 1",
                n.full_well_electrons
            );
        }
        let capture = Self { description, frames, tile_bands, defects, source: None, flat: None };
        let mask = capture.mask()?;
        ensure!(
            mask.snapshots() == capture.frames.len(),
            "mask has {} snapshots, capture has {} frames",
            mask.snapshots(),
            capture.frames.len()
        );
        Ok(capture)
    }

    /// Pixels at or above the saturation level over all frames, defective pixels left out,
    /// and all pixels.
    ///
    /// # Errors
    /// A paged frame's read that fails.
    pub fn saturated_pixels(&self) -> Result<(usize, usize)> {
        let sat = self.description.saturation_level;
        let (rows, cols) = self.frame_size();
        let mut count = 0;
        self.frames.visit((rows, cols), |_, first, values| {
            for (i, &x) in values.iter().enumerate() {
                let p = Pixel { row: (first + i / cols) as u16, col: (i % cols) as u16 };
                count += usize::from(f32::from(x) >= sat && self.defects.binary_search(&p).is_err());
            }
        })?;
        Ok((count, self.frames.len() * rows * cols))
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
        match &self.description.lenslet_grid {
            Some(g) => (g.sensor[0], g.sensor[1]),
            None => self.sensor().frame_size(),
        }
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

    /// The sensor's noise in the decoder's normalised units, `(noise, shot)` as
    /// [`Sl0Config`] takes them: a measurement `y` has variance `noise^2 + shot * max(y, 0)`.
    /// Read noise and the quantisation of whole DN (`1/12` DN^2) make the floor; shot noise
    /// is `1 / electrons at white` (a Poisson count's variance is its mean). `None` when
    /// the capture does not describe its noise.
    pub fn noise_model(&self) -> Option<(f32, f32)> {
        let d = &self.description;
        let n = d.noise?;
        let range = f64::from(d.white_level - d.black_level);
        let floor = (f64::from(n.read_noise_dn).powi(2) + 1.0 / 12.0) / (range * range);
        Some((floor.sqrt() as f32, (1.0 / f64::from(n.full_well_electrons)) as f32))
    }

    /// The firmware's tile decoder for this capture, for `5 x 5 x PU x PV x 13` patches.
    ///
    /// # Errors
    /// A mask or geometry the decoder does not take, with the reason.
    pub fn decoder<const PU: usize, const PV: usize, const N: usize>(
        &self,
        sl0: Sl0Config,
    ) -> Result<HostDecoder<'_, PU, PV, N>> {
        let mask = self.mask().map_err(|e| anyhow!("{}: {}", self.source(), one_line(&e)))?;
        let config =
            DecoderConfig { sensor: self.sensor(), mask, raw: self.raw_format(), defects: self.defects(), sl0 };
        let grid = match &self.description.lenslet_grid {
            Some(g) => Some(g.firmware(self.description.views)?),
            None => None,
        };
        TileDecoder::new(config)
            .and_then(|d| d.with_grid(grid))
            .map_err(|e| anyhow!("{}: the decoder does not take this capture: {e}", self.source()))
    }

    /// This capture read as if its lenslet array were aligned: `U x V` pixels under each
    /// lenslet from pixel (0, 0), the frames cut to `S*U x T*V`, no `lenslet_grid` (slf's
    /// reading before grids, which a turned array's capture is measured against).
    ///
    /// # Errors
    /// A sensor smaller than `S*U x T*V` (a pitch below the views).
    pub fn aligned(&self) -> Result<Self> {
        let d = &self.description;
        let (rows, cols) = (d.lenslets[0] * d.views[0], d.lenslets[1] * d.views[1]);
        let (r0, c0) = self.frame_size();
        ensure!(
            rows <= r0 && cols <= c0,
            "{}: read as aligned, {:?} lenslets of {:?} views need a {rows} x {cols} sensor, and it is {r0} x {c0}",
            self.source(),
            d.lenslets,
            d.views
        );
        let frames = self.frames.cropped((r0, c0), (rows, cols));
        let mut description = d.clone();
        description.lenslet_grid = None;
        description.defective_pixels.retain(|p| (p[0] as usize) < rows && (p[1] as usize) < cols);
        let mut c = Self::with_frames(description, frames)?;
        c.keep_source_of(self);
        Ok(c)
    }

    /// Names `other`'s folder as this capture's (a capture made from it: corrected, read
    /// as aligned), so errors say which capture, and keeps the flat its frames were
    /// divided by.
    pub fn keep_source_of(&mut self, other: &Self) {
        self.source.clone_from(&other.source);
        self.flat.clone_from(&other.flat);
    }

    /// The flat this capture's frames were divided by ([`Self::divided_by`]), read at the
    /// frame's rows and columns from the top left (a crop's too).
    pub fn flat(&self) -> Option<&Map> {
        self.flat.as_ref()
    }

    /// Says the frames were divided by `flat` (`decode::correction`).
    pub fn divided_by(&mut self, flat: Map) {
        self.flat = Some(flat);
    }

    /// The frames in memory, read whole if they are paged ([`Frames::held`]).
    ///
    /// # Errors
    /// Frames past the memory cap, or a read that fails.
    pub fn held_frames(&self) -> Result<std::borrow::Cow<'_, [Vec<u16>]>> {
        self.frames.held(self.frame_size())
    }

    /// The frames in memory for changing them ([`Frames::held_mut`]).
    ///
    /// # Errors
    /// As [`Self::held_frames`].
    pub fn held_frames_mut(&mut self) -> Result<&mut Vec<Vec<u16>>> {
        let size = self.frame_size();
        self.frames.held_mut(size)
    }

    /// The frames as the decoder reads them.
    ///
    /// # Errors
    /// A frame whose size differs from the description's (checked in `new`, so not expected).
    pub fn raw_frames(&self) -> Result<Vec<SensorFrame<'_>>> {
        self.frames.sensor(self.frame_size())
    }

    /// The defect list for the decoder.
    pub fn defects(&self) -> DefectList<'_> {
        // Sorted and deduplicated in `new`, so this cannot fail.
        DefectList::new(&self.defects).unwrap_or_default()
    }

    /// Loads a capture folder: frames of more than [`HOLD_BYTES`] in all are paged (read a
    /// band of rows at a time as the decode asks, where their format allows), smaller ones
    /// held.
    ///
    /// # Errors
    /// A message with the file and what is wrong in it.
    pub fn load(dir: &Path) -> Result<Self> {
        Self::load_with(dir, HOLD_BYTES)
    }

    /// [`Self::load`] with every `.npy` and PGM frame paged, whatever its size
    /// (tests and benchmarks of the paged reading).
    ///
    /// # Errors
    /// As [`Self::load`].
    pub fn load_paged(dir: &Path) -> Result<Self> {
        Self::load_with(dir, 0)
    }

    fn load_with(dir: &Path, hold_bytes: u64) -> Result<Self> {
        let desc_path = dir.join(DESCRIPTION);
        let named = |e: anyhow::Error| anyhow!("{}: {}", desc_path.display(), one_line(&e));
        let text = read_small_file(&desc_path, MAX_DESCRIPTION)?;
        let mut description: CaptureDescription = super::json::parse(&text)
            .map_err(|e| anyhow!("{}: invalid capture description: {e}", desc_path.display()))?;
        let records = description.files.take();
        let (rows, cols) = description.frame_size().map_err(named)?;
        ensure!(
            (1..=MAX_BANDS).contains(&description.frames.len()),
            "{}: frames lists {} files, expected 1..={MAX_BANDS} (one per snapshot)",
            desc_path.display(),
            description.frames.len()
        );
        let mut paths = Vec::with_capacity(description.frames.len());
        for (i, name) in description.frames.iter().enumerate() {
            let path =
                frame_path(dir, name).map_err(|e| anyhow!("{}: frames[{i}]: {}", desc_path.display(), one_line(&e)))?;
            inside(dir, &path).map_err(|e| anyhow!("{}: frames[{i}]: {}", desc_path.display(), one_line(&e)))?;
            paths.push(path);
        }
        // The frames are the ones written with this description, before any is read.
        match records {
            Some(records) => {
                let names: Vec<&str> = description.frames.iter().map(String::as_str).collect();
                verify(dir, &desc_path, &records, &names)?;
            }
            None => eprintln!(
                "note: {} records no sizes and checksums of its frames (written before slf checked them): a frame \
                 from another capture would not be noticed",
                desc_path.display()
            ),
        }
        let frames = {
            let fits = |path: &Path, top: u32| saturation_fits(&description, path, top);
            Frames::open(&paths, (rows, cols), hold_bytes, fits)?
        };
        let mut capture = Self::with_frames(description, frames).map_err(named)?;
        capture.source = Some(desc_path);
        Ok(capture)
    }

    /// Where the capture was loaded from (its `capture.json`), for messages.
    pub fn source(&self) -> String {
        self.source.as_ref().map_or_else(|| "the capture".into(), |p| p.display().to_string())
    }

    /// The files this capture has in folder `dir`: `capture.json` and its frames (names
    /// that are not paths inside the folder are left out; [`Self::new`] refuses them).
    pub fn files_in(&self, dir: &Path) -> Vec<PathBuf> {
        let frames = self.description.frames.iter().filter_map(|n| frame_path(dir, n).ok());
        std::iter::once(dir.join(DESCRIPTION)).chain(frames).collect()
    }

    /// The files the capture was loaded from: `capture.json` and its frames; none for a
    /// capture made in memory.
    pub fn files(&self) -> Vec<PathBuf> {
        match self.source.as_deref().and_then(Path::parent) {
            Some(dir) => self.files_in(dir),
            None => Vec::new(),
        }
    }

    /// Writes the capture folder: `capture.json` and the frames under their names
    /// (the extension picks the format: `.pgm`, `.png` or `.npy`).
    ///
    /// # Errors
    /// I/O and encoding errors, with the file.
    ///
    /// The folder is written whole ([`WholeFolder`]): into a temporary folder beside `dir`,
    /// renamed into place at the end, so a failure leaves the old folder as it was. An
    /// existing `dir` must be empty or a capture folder.
    pub fn save(&self, dir: &Path) -> Result<()> {
        self.stage(dir)?.persist()
    }

    /// As [`Self::save`], short of putting the folder in place: the caller persists it
    /// once everything written beside it is in too (`slf simulate` with calibration
    /// captures writes both or neither).
    ///
    /// # Errors
    /// As [`Self::save`].
    pub fn stage(&self, dir: &Path) -> Result<WholeFolder> {
        let folder = WholeFolder::create(dir, Kind::Files(DESCRIPTION, &[], is_frame_name))?;
        self.write_into(folder.path())?;
        Ok(folder)
    }

    /// Writes the capture's files into the existing folder `dir` (one being written whole:
    /// [`Self::save`]), the description last with each frame's size and CRC-32.
    ///
    /// # Errors
    /// I/O and encoding errors, with the file.
    pub fn write_into(&self, dir: &Path) -> Result<()> {
        let (rows, cols) = self.frame_size();
        let mut records = Vec::with_capacity(self.frames.len());
        let held = self.frames.held((rows, cols))?;
        for (name, data) in self.description.frames.iter().zip(held.iter()) {
            let path = dir.join(name);
            if let Some(parent) = path.parent() {
                fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
            }
            write_frame(&path, data, rows, cols)?;
            records.push(record(dir, name)?);
        }
        let description = CaptureDescription { files: Some(records), ..self.description.clone() };
        let text = serde_json::to_string_pretty(&description)?;
        write_bytes(&dir.join(DESCRIPTION), (text + "\n").as_bytes())
    }
}

/// The folder path's description file.
pub fn description_path(dir: &Path) -> PathBuf {
    dir.join(DESCRIPTION)
}

impl CaptureDescription {
    /// The lenslet grid the frames were taken through, unless it is the aligned one (which
    /// the decode reads as no grid).
    pub fn turned_grid(&self) -> Option<GridDescription> {
        self.lenslet_grid.filter(|g| !g.is_aligned(self.lenslets, self.views))
    }

    /// Checks the geometry, format and levels, and returns the frame size `(rows, cols)`.
    ///
    /// # Errors
    /// A message naming the field that is wrong and its range.
    pub fn frame_size(&self) -> Result<(usize, usize)> {
        ensure!(self.format == FORMAT, "format is {}, expected {FORMAT:?}", crate::io::message::quoted(&self.format));
        ensure!(
            self.version == VERSION || self.version == VERSION_SENSOR,
            "version {} is not supported (this slf reads {VERSION} and {VERSION_SENSOR})",
            self.version
        );
        if let Some(sensor) = &self.simulated_sensor {
            ensure!(
                self.version == VERSION_SENSOR,
                "simulated_sensor needs version {VERSION_SENSOR}, this capture says {}",
                self.version
            );
            sensor.check()?;
        }
        match self.light {
            Light::Scene => {}
            _ if self.version != VERSION_SENSOR => {
                bail!("light {:?} needs version {VERSION_SENSOR}, this capture says {}", self.light, self.version)
            }
            Light::Dark => {}
            Light::Flat { level } | Light::Band { level, .. } => ensure!(
                level.is_finite() && level > 0.0 && level <= 1.0,
                "light level {}: must be in (0, 1] (a fraction of white)",
                crate::io::message::number(level)
            ),
        }
        if let Light::Band { band, .. } = self.light {
            ensure!(
                usize::from(band) < self.bands_nm.len(),
                "light band {band}: the capture has {} bands (0..={})",
                self.bands_nm.len(),
                self.bands_nm.len().saturating_sub(1)
            );
        }
        ensure!(
            self.lenslets.iter().all(|&x| (1..=usize::from(u16::MAX)).contains(&x)),
            "lenslets {:?} out of range 1..={}",
            self.lenslets,
            u16::MAX
        );
        ensure!(self.views.iter().all(|&x| (1..=255).contains(&x)), "views {:?} out of range 1..=255", self.views);
        let rows = self.lenslets[0].checked_mul(self.views[0]);
        let cols = self.lenslets[1].checked_mul(self.views[1]);
        let (Some(rows), Some(cols)) = (rows, cols) else {
            bail!("lenslets {:?} x views {:?} overflows", self.lenslets, self.views);
        };
        ensure!(
            rows <= usize::from(u16::MAX) && cols <= usize::from(u16::MAX),
            "lenslets {:?} x views {:?} is a {rows} x {cols} frame, at most {} x {}",
            self.lenslets,
            self.views,
            u16::MAX,
            u16::MAX
        );
        let (rows, cols) = match &self.lenslet_grid {
            None => (rows, cols),
            Some(g) => {
                ensure!(
                    self.version == VERSION_SENSOR,
                    "lenslet_grid needs version {VERSION_SENSOR}, this capture says {}",
                    self.version
                );
                g.check(self.lenslets, self.views)?;
                ensure!(
                    matches!(self.mask, MaskDescription::Pixel(_)),
                    "lenslet_grid with a {} mask: its filters sit on the lenslets, and only a pixel mask (a filter \
                     per sensor pixel) is modelled behind a lenslet grid",
                    self.mask.family_name()
                );
                (g.sensor[0], g.sensor[1])
            }
        };
        ensure!(
            (1..=32).contains(&self.bands_nm.len()),
            "bands_nm has {} entries, expected 1..=32",
            self.bands_nm.len()
        );
        // Wavelengths a filter can have, each band once, in order: the bands' order is the
        // light field's band axis, and a duplicate or a reversed list names bands wrongly.
        if let Some((i, w)) = self.bands_nm.iter().enumerate().find(|(_, w)| !(MIN_NM..=MAX_NM).contains(*w)) {
            bail!(
                "bands_nm[{i}] is {} nm: each must be in {MIN_NM}..={MAX_NM} nm (ultraviolet to short-wave infrared)",
                crate::io::message::number(*w)
            );
        }
        if let Some(i) = self.bands_nm.windows(2).position(|p| p[1] <= p[0]) {
            bail!(
                "bands_nm[{}] is {} nm after {} nm: the bands must be listed in increasing wavelength, each once",
                i + 1,
                self.bands_nm[i + 1],
                self.bands_nm[i]
            );
        }
        ensure!(
            self.black_level.is_finite()
                && self.white_level.is_finite()
                && self.saturation_level.is_finite()
                && self.white_level > self.black_level
                && self.saturation_level > self.black_level,
            "levels: need finite black_level < white_level and black_level < saturation_level"
        );
        // Frames hold 16-bit values: a black level outside them is no sensor's, and one of
        // -3e38 under a white of 3e38 made white - black infinite and the decode all zeros.
        ensure!(
            (0.0..=65535.0).contains(&self.black_level),
            "black_level {}: must be in 0..=65535 (the frames' 16-bit values)",
            crate::io::message::number(self.black_level)
        );
        ensure!(
            (self.white_level - self.black_level).is_finite(),
            "levels: white_level - black_level is not a finite number"
        );
        Ok((rows, cols))
    }
}

/// A capture's frames of at most this many bytes in all are held when it is loaded, larger
/// ones paged: reading through the band cache takes about 1.06 x the CPU time of a default
/// decode of held frames (0.98-1.13 over 10 pairs; office, 80 x 80 lenslets, pixel k = 1,
/// 2 threads, `farm-bench` paired; 1.14 x before each thread kept its last bands), and
/// holding costs at most this (a 4096 x 4096 sensor at one snapshot).
pub const HOLD_BYTES: u64 = 32 << 20;

/// A frame file whose largest value (`top`: its MAXVAL or bit depth) reaches the capture's
/// saturation level: below it, saturated pixels would read as measurements.
///
/// # Errors
/// One that does not, naming the file.
fn saturation_fits(description: &CaptureDescription, path: &Path, top: u32) -> Result<()> {
    ensure!(
        description.saturation_level <= top as f32,
        "{}: the file's largest value is {top} (its MAXVAL or bit depth), below saturation_level {} in {}: \
         saturated pixels would read as measurements",
        path.display(),
        description.saturation_level,
        DESCRIPTION
    );
    Ok(())
}

//! The calibration file (issue 43): what `slf calibrate` learns of a sensor from its
//! calibration captures, and what a calibrated decode corrects with. A folder:
//! `calibration.json` (geometry, levels, the response matrix, vignetting per view, hot
//! pixels) and two float32 `.npy` frames, each pixel's dark level (DN) and its flat (gain
//! times its view's vignetting, 1 for an ideal pixel). Everything is checked on load, sizes
//! before anything is allocated (`docs/capture-format.md`, "Calibration").

use std::path::{Path, PathBuf};

use anyhow::{Result, anyhow, bail, ensure};

use crate::io::folder::{FileRecord, Kind, WholeFolder, record, verify};
use serde::{Deserialize, Serialize};

use crate::io::capture::MAX_DESCRIPTION;
use crate::io::file_checks::read_small_file;
use crate::io::grid::GridDescription;
use crate::io::lightfield::write_npy_f32_2d;
use crate::io::map::Map;
use crate::io::message::number;
use crate::io::npy::{self, Element, Values};
use crate::io::output::write_bytes;
use crate::io::row_reader::RowReader;

/// The description file's name inside a calibration folder.
pub const DESCRIPTION: &str = "calibration.json";
/// The `format` field's value.
pub const FORMAT: &str = "slf-calibration";
/// The `version` field's value.
pub const VERSION: u32 = 1;
/// The dark levels' file.
pub const DARK: &str = "dark.npy";
/// The flats' file.
pub const FLAT: &str = "flat.npy";

/// How many calibration captures of each kind went into a calibration (informational).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sources {
    pub dark: usize,
    pub flat: usize,
    pub band: usize,
}

/// `calibration.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationDescription {
    pub format: String,
    pub version: u32,
    /// `[S, T]`, as the captures it decodes.
    pub lenslets: [usize; 2],
    /// `[U, V]`.
    pub views: [usize; 2],
    pub bands_nm: Vec<f32>,
    /// The captures' black and white levels (DN) the flat and response are relative to.
    pub black_level: f32,
    pub white_level: f32,
    /// `response[f][b]`: what a pixel behind filter `f` records of band `b`, relative to
    /// its response to light of equal energy in every band (a row sums to about 1).
    pub response: Vec<Vec<f32>>,
    /// `vignetting[u][v]`: view `(u, v)`'s mean flat over the sensor, relative to the
    /// brightest view's: the compact model of the flat (the device's table).
    pub vignetting: Vec<Vec<f32>>,
    /// `[row, col]` of pixels whose dark level or flat is no working pixel's.
    pub hot_pixels: Vec<[u32; 2]>,
    /// `[row, col]` of pixels behind a lenslet grid that no lenslet of the array lights
    /// (their centres lie in no view cell of the array: a turned array's sensor edges):
    /// dark in the flats, yet not dead. No patch reads them. Absent when empty.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outside_pixels: Vec<[u32; 2]>,
    pub sources: Sources,
    /// The lenslet grid found from the flats ([`crate::io::grid`]), when the captures were
    /// taken behind one; the frames are then its sensor's size.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lenslet_grid: Option<GridDescription>,
    /// `dark.npy`'s and `flat.npy`'s sizes and CRC-32s as written ([`crate::io::folder`]),
    /// checked on load; a loaded calibration's description holds none. Absent in folders
    /// written before they were (loaded with a note).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub files: Option<Vec<FileRecord>>,
}

/// Measured filter curves: a float `.npy` of shape `(bands, bands)`, `[filter][band]` as
/// [`CalibrationDescription::response`] holds them; the shape checked from the header.
///
/// # Errors
/// The file and what is wrong in it.
pub fn read_response(path: &Path, bands: usize) -> Result<Vec<Vec<f32>>> {
    let a = npy::read_checked(path, |s, element| {
        if s != [bands, bands] {
            return Err(format!("is {s:?}: filter curves are (filters, bands) = ({bands}, {bands})"));
        }
        if element == Element::U16 {
            return Err("holds uint16: filter curves are floats".into());
        }
        Ok(())
    })
    .map_err(|e| anyhow!("{e}"))?;
    match a.values {
        Values::F32(v) => Ok(v.chunks(bands).map(<[f32]>::to_vec).collect()),
        Values::U16(_) => Err(anyhow!("{}: filter curves are floats", path.display())),
    }
}

/// A calibration map's header: the calibration's frame size, floats.
fn map_header(s: &[usize], element: Element, (rows, cols): (usize, usize)) -> Result<(), String> {
    if s != [rows, cols] {
        return Err(format!("is {s:?}, the calibration's frame [{rows}, {cols}]"));
    }
    if element == Element::U16 {
        return Err("holds uint16, a calibration frame float32".into());
    }
    Ok(())
}

/// A loaded calibration.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    pub description: CalibrationDescription,
    /// Each pixel's dark level, DN, row-major.
    pub dark: Vec<f32>,
    /// Each pixel's flat: its gain times its view's vignetting (1: an ideal pixel).
    pub flat: Vec<f32>,
}

impl CalibrationDescription {
    /// The frame size `(rows, cols)`, with every field checked.
    ///
    /// # Errors
    /// The first field out of its range, named.
    pub fn check(&self) -> Result<(usize, usize)> {
        ensure!(self.format == FORMAT, "format is {}, expected {FORMAT:?}", crate::io::message::quoted(&self.format));
        ensure!(self.version == VERSION, "version {} is not supported (this slf reads {VERSION})", self.version);
        ensure!(
            self.lenslets.iter().all(|&x| (1..=usize::from(u16::MAX)).contains(&x))
                && self.views.iter().all(|&x| (1..=255).contains(&x)),
            "lenslets {:?} or views {:?} out of range",
            self.lenslets,
            self.views
        );
        let (rows, cols) = (self.lenslets[0] * self.views[0], self.lenslets[1] * self.views[1]);
        ensure!(
            rows <= usize::from(u16::MAX) && cols <= usize::from(u16::MAX),
            "lenslets {:?} x views {:?} is a {rows} x {cols} frame, at most 65535 x 65535",
            self.lenslets,
            self.views
        );
        let (rows, cols) = match &self.lenslet_grid {
            Some(g) => {
                g.check(self.lenslets, self.views)?;
                (g.sensor[0], g.sensor[1])
            }
            None => (rows, cols),
        };
        let b = self.bands_nm.len();
        ensure!((2..=32).contains(&b), "bands_nm has {b} entries, expected 2..=32");
        ensure!(
            self.black_level.is_finite()
                && self.white_level.is_finite()
                && (0.0..=65535.0).contains(&self.black_level)
                && self.white_level > self.black_level,
            "levels: need 0 <= black_level < white_level, finite"
        );
        ensure!(self.response.len() == b, "response has {} rows, expected {b} (one a filter)", self.response.len());
        if let Some((f, row)) = self.response.iter().enumerate().find(|(_, r)| r.len() != b) {
            bail!("response[{f}] has {} entries, expected {b} (one a band)", row.len());
        }
        check_response(&self.response)?;
        ensure!(
            self.vignetting.len() == self.views[0] && self.vignetting.iter().all(|r| r.len() == self.views[1]),
            "vignetting is not {} x {} (views)",
            self.views[0],
            self.views[1]
        );
        if let Some(x) = self.vignetting.iter().flatten().find(|x| !(x.is_finite() && **x > 0.0 && **x <= 1.5)) {
            return Err(anyhow!("vignetting holds {}: each view's must be in (0, 1.5]", number(*x)));
        }
        if let Some(p) = self.hot_pixels.iter().find(|p| p[0] as usize >= rows || p[1] as usize >= cols) {
            return Err(anyhow!("hot pixel {p:?} outside the {rows} x {cols} frame"));
        }
        ensure!(
            self.outside_pixels.is_empty() || self.lenslet_grid.is_some(),
            "outside_pixels listed without a lenslet_grid: only a grid leaves pixels outside the array"
        );
        if let Some(p) = self.outside_pixels.iter().find(|p| p[0] as usize >= rows || p[1] as usize >= cols) {
            return Err(anyhow!("outside pixel {p:?} outside the {rows} x {cols} frame"));
        }
        Ok((rows, cols))
    }
}

/// The largest condition number of a response matrix a decode inverts: beyond it the
/// unmixing would amplify noise more than the leakage it removes.
pub const MAX_CONDITION: f64 = 1e3;

/// How far a response row's sum may be from 1: a row is relative to the filter's response
/// to light of equal energy in every band, so it sums to 1 up to the calibration's noise
/// (within 1e-3 on the simulator's sensors). Rows of another scale would rescale the
/// output by their inverse (0.3 x a valid matrix made every value 3.33 x).
pub const ROW_SUM_TOLERANCE: f32 = 0.1;

/// Checks a square response matrix `[filter][band]` as a decode needs it: entries finite in
/// [-0.1, 2], every filter seeing its own band, rows summing to 1 within
/// [`ROW_SUM_TOLERANCE`], and a condition number of at most [`MAX_CONDITION`].
///
/// # Errors
/// The first entry, row or the matrix that is not, in one line.
pub fn check_response(response: &[Vec<f32>]) -> Result<()> {
    for (f, row) in response.iter().enumerate() {
        if let Some(x) = row.iter().find(|x| !(x.is_finite() && (-0.1..=2.0).contains(*x))) {
            return Err(anyhow!("response[{f}] holds {}: each entry must be in [-0.1, 2]", number(*x)));
        }
        ensure!(row[f] > 0.0, "response[{f}][{f}] is {}: a filter must see its own band", number(row[f]));
        let sum: f32 = row.iter().sum();
        ensure!(
            (sum - 1.0).abs() <= ROW_SUM_TOLERANCE,
            "response[{f}] sums to {}: a filter's row is relative to light of equal energy in every band and sums \
             to 1 (within {ROW_SUM_TOLERANCE}); scale measured curves so that each row sums to 1",
            number(sum)
        );
    }
    let b = response.len();
    let r = nalgebra::DMatrix::from_fn(b, b, |f, band| f64::from(response[f][band]));
    let sv = r.singular_values();
    let (hi, lo) = (sv.max(), sv.min());
    ensure!(
        lo > 0.0 && hi / lo <= MAX_CONDITION,
        "the response matrix's condition number is {:.3e} (at most {MAX_CONDITION:e}): the filters do not tell the \
         bands apart",
        hi / lo
    );
    Ok(())
}

/// A working pixel's dark level lies between 0 and half-way up the range, `black + (white -
/// black) / 2` DN: above, a pixel records less than half the light it should and is no
/// working pixel (a calibration lists it in `hot_pixels`). A dark level at or above the raw
/// values once made every output zero, and one of -65535 every value 18.05.
fn check_dark(d: &CalibrationDescription, dark: &[f32], cols: usize) -> Result<()> {
    check_dark_rows(d, &hot_indices(d, cols), 0, dark, cols)
}

/// The hot and outside pixels' row-major indices in a frame of `cols` columns (neither is a
/// working pixel whose dark level is checked).
fn hot_indices(d: &CalibrationDescription, cols: usize) -> std::collections::BTreeSet<usize> {
    d.hot_pixels.iter().chain(&d.outside_pixels).map(|p| p[0] as usize * cols + p[1] as usize).collect()
}

/// [`check_dark`] on the rows from `first_row` on (`dark` holds whole rows).
fn check_dark_rows(
    d: &CalibrationDescription,
    hot: &std::collections::BTreeSet<usize>,
    first_row: usize,
    dark: &[f32],
    cols: usize,
) -> Result<()> {
    let top = d.black_level + (d.white_level - d.black_level) / 2.0;
    for (i, &x) in dark.iter().enumerate().map(|(i, x)| (first_row * cols + i, x)) {
        let (lo, hi) = if hot.contains(&i) { (0.0, 65535.0) } else { (0.0, top) };
        if !(x.is_finite() && (lo..=hi).contains(&x)) {
            let working =
                if hot.contains(&i) { "a hot pixel's" } else { "a working pixel's (else list it in hot_pixels)" };
            bail!("dark[{}, {}] is {} DN: {working} dark level is in [{lo}, {hi}]", i / cols, i % cols, number(x));
        }
    }
    Ok(())
}

/// Every flat finite in [0, 16] (a flat of 0 is a dead pixel: list it as hot).
fn check_flat(flat: &[f32], cols: usize) -> Result<()> {
    check_flat_rows(0, flat, cols)
}

/// [`check_flat`] on the rows from `first_row` on.
fn check_flat_rows(first_row: usize, flat: &[f32], cols: usize) -> Result<()> {
    if let Some(i) = flat.iter().position(|x| !(x.is_finite() && (0.0..=16.0).contains(x))) {
        let p = first_row * cols + i;
        bail!("flat[{}, {}] is {}: must be in [0, 16]", p / cols, p % cols, number(flat[i]));
    }
    Ok(())
}

/// A calibration opened for a corrected decode: its description, checked as
/// [`Calibration::load`] checks it, and its maps read by rows ([`Map`]).
#[derive(Clone, Debug)]
pub struct OpenCalibration {
    pub description: CalibrationDescription,
    pub dark: Map,
    pub flat: Map,
}

impl OpenCalibration {
    /// The frame size.
    pub fn frame_size(&self) -> (usize, usize) {
        frame_size(&self.description)
    }
}

/// A calibration's frame size, from its description.
fn frame_size(d: &CalibrationDescription) -> (usize, usize) {
    match &d.lenslet_grid {
        Some(g) => (g.sensor[0], g.sensor[1]),
        None => (d.lenslets[0] * d.views[0], d.lenslets[1] * d.views[1]),
    }
}

impl Calibration {
    /// Checks the description and the frames against each other.
    ///
    /// # Errors
    /// A field out of range, a frame of another size, a dark level or flat that is not a
    /// finite number in range (a flat of 0 is a dead pixel: list it as hot).
    pub fn new(description: CalibrationDescription, dark: Vec<f32>, flat: Vec<f32>) -> Result<Self> {
        let (rows, cols) = description.check()?;
        ensure!(
            dark.len() == rows * cols && flat.len() == rows * cols,
            "dark and flat hold {} and {} values, the frame {rows} x {cols}",
            dark.len(),
            flat.len()
        );
        check_dark(&description, &dark, cols)?;
        check_flat(&flat, cols)?;
        Ok(Self { description, dark, flat })
    }

    /// The frame size.
    pub fn frame_size(&self) -> (usize, usize) {
        frame_size(&self.description)
    }

    /// This calibration as a decode reads it, its maps held (copies).
    pub fn opened(&self) -> OpenCalibration {
        let (_, cols) = self.frame_size();
        OpenCalibration {
            description: self.description.clone(),
            dark: Map::Held(self.dark.as_slice().into(), cols),
            flat: Map::Held(self.flat.as_slice().into(), cols),
        }
    }

    /// The response matrix row-major, `[filter][band]`.
    pub fn response(&self) -> Vec<f32> {
        self.description.response.iter().flatten().copied().collect()
    }

    /// Reads a calibration folder.
    ///
    /// # Errors
    /// The file and what is wrong in it.
    pub fn load(dir: &Path) -> Result<Self> {
        let (description, (rows, cols)) = Self::description_in(dir)?;
        let read = |name: &str| -> Result<Vec<f32>> {
            let p: PathBuf = dir.join(name);
            let a =
                npy::read_checked(&p, |s, element| map_header(s, element, (rows, cols))).map_err(|e| anyhow!("{e}"))?;
            match a.values {
                Values::F32(v) => Ok(v),
                Values::U16(_) => Err(anyhow!("{}: holds uint16, a calibration frame float32", p.display())),
            }
        };
        // Each fault names its file.
        let (dark, flat) = (read(DARK)?, read(FLAT)?);
        check_dark(&description, &dark, cols).map_err(|e| anyhow!("{}: {e}", dir.join(DARK).display()))?;
        check_flat(&flat, cols).map_err(|e| anyhow!("{}: {e}", dir.join(FLAT).display()))?;
        // Every check of `new` is done: the description above, the frames' shapes from
        // their headers, their values just now (each naming its file).
        Ok(Self { description, dark, flat })
    }

    /// Opens a calibration folder for a corrected decode: every check of [`Self::load`],
    /// the maps' values checked in one pass of bands, and then read by rows as the decode
    /// asks ([`Map::File`]; a map stored in Fortran order is read whole).
    ///
    /// # Errors
    /// As [`Self::load`].
    pub fn open(dir: &Path) -> Result<OpenCalibration> {
        let (description, size) = Self::description_in(dir)?;
        let open = |name: &str| -> Result<Map> {
            let p: PathBuf = dir.join(name);
            match RowReader::open_npy(&p, |s, element| map_header(s, element, size)).map_err(|e| anyhow!("{e}"))? {
                Some(r) => Ok(Map::File(r)),
                None => match npy::read_checked(&p, |s, element| map_header(s, element, size))
                    .map_err(|e| anyhow!("{e}"))?
                    .values
                {
                    Values::F32(v) => Ok(Map::Held(v.into(), size.1)),
                    Values::U16(_) => Err(anyhow!("{}: holds uint16, a calibration frame float32", p.display())),
                },
            }
        };
        let (dark, flat) = (open(DARK)?, open(FLAT)?);
        let cols = size.1;
        let hot = hot_indices(&description, cols);
        dark.visit(size, |first, v| check_dark_rows(&description, &hot, first, v, cols))
            .map_err(|e| anyhow!("{}: {e}", dir.join(DARK).display()))?;
        flat.visit(size, |first, v| check_flat_rows(first, v, cols))
            .map_err(|e| anyhow!("{}: {e}", dir.join(FLAT).display()))?;
        Ok(OpenCalibration { description, dark, flat })
    }

    /// The description of the calibration in `dir`, checked, its maps' files verified
    /// against the sizes and checksums it records; and the frame size.
    fn description_in(dir: &Path) -> Result<(CalibrationDescription, (usize, usize))> {
        let path = dir.join(DESCRIPTION);
        let text = read_small_file(&path, MAX_DESCRIPTION)?;
        let mut description: CalibrationDescription =
            super::json::parse(&text).map_err(|e| anyhow!("{}: invalid calibration: {e}", path.display()))?;
        match description.files.take() {
            // A flat from another calibration beside these dark levels once decoded with
            // exit 0.
            Some(records) => verify(dir, &path, &records, &[DARK, FLAT])?,
            None => eprintln!(
                "note: {} records no sizes and checksums of {DARK} and {FLAT} (written before slf checked them): \
                 files from another calibration would not be noticed",
                path.display()
            ),
        }
        let size = description.check().map_err(|e| anyhow!("{}: {e}", path.display()))?;
        Ok((description, size))
    }

    /// The files a calibration has in folder `dir`.
    pub fn files_in(dir: &Path) -> [PathBuf; 3] {
        [DESCRIPTION, DARK, FLAT].map(|name| dir.join(name))
    }

    /// Writes the calibration folder, each file whole.
    ///
    /// # Errors
    /// I/O errors, with the file.
    ///
    /// The folder is written whole ([`WholeFolder`]): a failure leaves the old folder as it
    /// was (before, a failed write could leave new dark levels beside old flats). An
    /// existing `dir` must be empty or a calibration folder.
    pub fn save(&self, dir: &Path) -> Result<()> {
        // A calibration's files are the fixed two; its `files` names nothing more to replace.
        let folder = WholeFolder::create(dir, Kind::Files(DESCRIPTION, &[DARK, FLAT], |_| false))?;
        let at = folder.path();
        let (rows, cols) = self.frame_size();
        write_npy_f32_2d(&at.join(DARK), &self.dark, rows, cols)?;
        write_npy_f32_2d(&at.join(FLAT), &self.flat, rows, cols)?;
        let files = Some(vec![record(at, DARK)?, record(at, FLAT)?]);
        let description = CalibrationDescription { files, ..self.description.clone() };
        let text = serde_json::to_string_pretty(&description)?;
        write_bytes(&at.join(DESCRIPTION), (text + "\n").as_bytes())?;
        folder.persist()
    }
}

//! What a decode did ([`DecodeReport`]): its counts, which decoder made each patch, the
//! disparities and error estimates by patch and per lenslet, and the trials' findings.

use slf_firmware::disparity::Disparity;
use slf_firmware::{Ended, PatchOrigin, PatchReport, TileReport};

use crate::decode::options::PatchViews;
use crate::io::grid::{GridDescription, OffSensor};
use crate::io::patch::BANDS;

/// Which decoder made a patch: a row of [`DecodeReport::member_map`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchDecoder {
    /// SL0 with this ensemble member (the last solve's).
    Member(u16),
    /// SL0 with the single dictionary (the DCT, or a one-member basis).
    Dictionary,
    /// Per-pixel spectral interpolation: the patch measured fewer than `min_bands` bands.
    Interpolated,
    /// The flat short path: each band its mean, no solve.
    Flat,
}

impl PatchDecoder {
    /// The decoder of a patch from its report.
    pub fn of(report: &PatchReport) -> Self {
        match (report.outcome.ended, report.member) {
            (Ended::Interpolated, _) => Self::Interpolated,
            (Ended::Flat, _) => Self::Flat,
            (_, Some(m)) => Self::Member(m),
            (_, None) => Self::Dictionary,
        }
    }

    /// Its name in the member map's `decoder` column.
    pub fn name(self) -> &'static str {
        match self {
            Self::Member(_) => "member",
            Self::Dictionary => "dictionary",
            Self::Interpolated => "interpolated",
            Self::Flat => "flat",
        }
    }
}

/// What a decode did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DecodeReport {
    pub patches: TileReport,
    pub tiles: usize,
    pub failed_tiles: usize,
    /// SL0 steps over all patches (the last solve of each).
    pub steps: u64,
    /// Solves over all patches (more than one per patch with an ensemble).
    pub solves: u64,
    /// Which decoder made each decoded patch, by patch origin: the ensemble member, the
    /// single dictionary, interpolation or the flat short path (empty unless asked for:
    /// [`crate::decode::options::Maps`]).
    pub member_map: Vec<(PatchOrigin, PatchDecoder)>,
    /// Light-field values no decoded patch covered (left at 0).
    pub uncovered: usize,
    /// Values of a view no (sheared) patch covered, taken from the lenslet's other views.
    pub filled: usize,
    /// The disparity each spatial block was sheared to, by its first patch's origin
    /// (empty when the decode searched no disparity, or the map was not asked for:
    /// [`crate::decode::options::Maps`]).
    pub disparity_map: Vec<(PatchOrigin, Disparity)>,
    /// How many blocks were sheared to each disparity, in increasing order (kept whether
    /// or not the map is).
    pub disparity_counts: Vec<(Disparity, usize)>,
    /// The most lenslet rows of sums the streamed decode held at once (each row's sums, 4
    /// bytes a value, and a weight a pixel, 4 bytes for its 13 values), besides a batch's
    /// tiles: what its memory grows with, bounded by the tiles' height, not the frame's
    /// ([`crate::decode::strip`]).
    pub rows_held: usize,
    /// The bytes of the streamed decode's strip: the slots of [`Self::rows_held`]'s sums and
    /// of the seed rows (the seeds' spectra, 4 bytes a value, when seeded or adaptive).
    pub strip_bytes: usize,
    /// The lenslet rows of seeds the strip holds (0 unseeded).
    pub seed_rows: usize,
    /// Wall time, seconds.
    pub seconds: f64,
    /// The band gains the decode used (1 without white balance).
    pub gains: [f32; BANDS],
    /// The patch it decoded with (`None` only in a report made by hand).
    pub patch_views: Option<PatchViews>,
    /// Each estimated patch's error estimate (RMS per value, the output's units), by
    /// origin ([`crate::decode::options::DecodeOptions::error_estimate`]; empty without it).
    pub error_map: Vec<(PatchOrigin, f32)>,
    /// The error estimate per lenslet of the decode made (row-major, RMS per value, the
    /// output's units), from its held-out decode ([`crate::decode::held_out`]; empty
    /// without it).
    pub error_lenslets: Vec<f32>,
    /// The held-out decode's wall time, seconds (0 without it; in [`Self::seconds`] too).
    pub estimate_seconds: f64,
    /// What the baseline blend did ([`crate::decode::blend`]; `None` without it).
    pub blend: Option<BlendReport>,
    /// Why the baseline blend was asked for and not made (the decode alone was put out).
    pub blend_skipped: Option<String>,
    /// What the model trial picked ([`crate::decode::options::DecodeOptions::model_trial`]; `None` without it).
    pub trial: Option<TrialReport>,
    /// What the shear trial found ([`crate::decode::options::DecodeOptions::shear_trial`]; `None` without it or
    /// without half-pixel disparities).
    pub shear_trial: Option<ShearTrialReport>,
    /// Why the shear trial was asked for and not run (no half-pixel disparity to try).
    pub shear_trial_skipped: Option<String>,
    /// The lenslet grid the decode read the frames through (`None`: the aligned sensor).
    pub grid: Option<GridDescription>,
    /// The whole lenslets `(s, t)` a calibration's grid was moved by to name its lenslets
    /// as the capture does ([`GridDescription::indexed_as`]; `[0, 0]` when they agreed).
    pub grid_moved: [i64; 2],
    /// What that grid puts off the sensor: views never measured, their values guessed from
    /// their neighbours (a turned array's corners; none on the aligned grid).
    pub off_sensor: OffSensor,
}

/// The shear trial's finding in a decode ([`crate::decode::trial::frame_shear_trial`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShearTrialReport {
    /// Pilot patches at a half-pixel disparity that estimated both.
    pub pilots: u32,
    /// Whether the decode kept its half-pixel disparities (else whole ones only).
    pub halves: bool,
    /// The held-out error estimate at the half-pixel disparities (RMS over the pilots).
    pub half_error: f64,
    /// At the better whole disparity beside each.
    pub whole_error: f64,
}

/// The baseline blend of a decode ([`crate::decode::blend`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BlendReport {
    /// Seconds its held-out decodes and PPIDs took (included in the decode's).
    pub seconds: f64,
    /// PPID's weight per lenslet, row-major (the decode's is one less).
    pub weights: Vec<f32>,
}

impl BlendReport {
    /// PPID's weight averaged over the lenslets.
    pub fn mean_weight(&self) -> f64 {
        self.weights.iter().map(|&w| f64::from(w)).sum::<f64>() / self.weights.len().max(1) as f64
    }

    /// Lenslets whose values are more PPID's than the decode's (weight above one half).
    pub fn mostly_baseline(&self) -> usize {
        self.weights.iter().filter(|&&w| w > 0.5).count()
    }
}

/// The model trial's picks in a decode ([`crate::decode::trial`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrialReport {
    /// Pilot patches that estimated both models.
    pub pilots: u32,
    /// Whether the DCT decoded the frame (else the ensemble).
    pub dct: bool,
    /// The DCT's held-out error estimate over the pilots (RMS, the output's units).
    pub dct_error: f64,
    /// The ensemble's.
    pub ensemble_error: f64,
    /// Whether the pilots tied (their difference within [`slf_firmware::TIE_SPREAD`] of its
    /// standard error), so the mask's and snapshot count's prior model decoded the frame
    /// ([`slf_firmware::dct_where_tied`]); false for a trial that leans by a margin (the
    /// preview's).
    pub tied: bool,
    /// With the trial by held-out decodes ([`crate::decode::options::TrialBy::Decode`]):
    /// the DCT's and the ensemble's error estimates of the frame from them (RMS, the
    /// output's units), which picked.
    pub by_decode: Option<(f64, f64)>,
}

/// The disparity per lenslet (row-major, `rows x cols`) from a decode's
/// [`DecodeReport::disparity_map`]: the mean of the chosen disparities of the 5 x 5 blocks
/// that cover the lenslet (overlapping blocks at a stride below 5), NaN where none does.
pub fn disparity_per_lenslet(blocks: &[(PatchOrigin, Disparity)], rows: usize, cols: usize) -> Vec<f32> {
    per_lenslet(blocks.iter().map(|(o, d)| (o, f64::from(d.as_f32()))), rows, cols, |mean| mean)
}

/// `finish` of the mean of the values of the 5 x 5-lenslet blocks (by their origins) that
/// cover each lenslet (row-major, `rows x cols`), NaN where none does.
fn per_lenslet<'a>(
    blocks: impl Iterator<Item = (&'a PatchOrigin, f64)>,
    rows: usize,
    cols: usize,
    finish: impl Fn(f64) -> f64,
) -> Vec<f32> {
    let mut sum = vec![0.0f64; rows * cols];
    let mut count = vec![0u32; rows * cols];
    for (o, x) in blocks {
        for r in o.lenslet_row as usize..(o.lenslet_row as usize + 5).min(rows) {
            for c in o.lenslet_col as usize..(o.lenslet_col as usize + 5).min(cols) {
                sum[r * cols + c] += x;
                count[r * cols + c] += 1;
            }
        }
    }
    sum.iter().zip(&count).map(|(&s, &n)| if n > 0 { finish(s / f64::from(n)) as f32 } else { f32::NAN }).collect()
}

/// The error estimate per lenslet (row-major, `rows x cols`) from a decode's
/// [`DecodeReport::error_map`]: the RMS of the estimates of the patches whose 5 x 5
/// lenslets cover it (every angular window, every overlapping patch), NaN where none does.
pub fn error_per_lenslet(patches: &[(PatchOrigin, f32)], rows: usize, cols: usize) -> Vec<f32> {
    per_lenslet(patches.iter().map(|(o, e)| (o, f64::from(*e) * f64::from(*e))), rows, cols, f64::sqrt)
}

impl DecodeReport {
    /// The error estimate per lenslet (row-major, `rows x cols`): the held-out decode's
    /// ([`Self::error_lenslets`]), else the patches' ([`error_per_lenslet`]); `None`
    /// without an estimate.
    pub fn error_per_lenslet(&self, rows: usize, cols: usize) -> Option<Vec<f32>> {
        if !self.error_lenslets.is_empty() {
            return Some(self.error_lenslets.clone());
        }
        (!self.error_map.is_empty()).then(|| error_per_lenslet(&self.error_map, rows, cols))
    }

    /// As [`Self::error_per_lenslet`], and with `asked` (an estimate was asked for) NaN
    /// everywhere where no patch could be estimated ([`NO_ESTIMATE`]): a map asked for is
    /// always written, never silently left out.
    pub fn error_map(&self, rows: usize, cols: usize, asked: bool) -> Option<Vec<f32>> {
        self.error_per_lenslet(rows, cols).or_else(|| asked.then(|| vec![f32::NAN; rows * cols]))
    }

    /// The PSNR error map `map` (`cols` lenslets a row) estimates for a light field spanning
    /// `data_range`, the lenslets that reach past the sensor left out ([`OffSensor::left_out`]:
    /// their guessed views are no figure of the decode's).
    pub fn estimated_psnr(&self, map: &[f32], cols: usize, data_range: f64) -> Option<f64> {
        estimated_psnr(&self.off_sensor.left_out(map, cols), data_range)
    }

    /// Whether an estimate was made: a patch's or a held-out decode's.
    pub fn estimated(&self) -> bool {
        !self.error_lenslets.is_empty() || !self.error_map.is_empty()
    }
}

/// Why an error map asked for is NaN everywhere.
pub const NO_ESTIMATE: &str = "no patch could be estimated (with a response that mixes bands, `--response-model \
                               projection`, a held-out measurement has no decoded value to be compared with); the \
                               error map is NaN everywhere";

/// The PSNR an error map estimates for a light field whose values span `data_range`: the
/// mean squared error is the mean of the lenslets' squared estimates (NaN ones left out);
/// `None` if none is finite.
pub fn estimated_psnr(map: &[f32], data_range: f64) -> Option<f64> {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for e in map.iter().filter(|e| e.is_finite()) {
        sum += f64::from(*e) * f64::from(*e);
        n += 1;
    }
    (n > 0).then(|| 10.0 * (data_range * data_range / (sum / n as f64).max(1e-20)).log10())
}

//! Baselines: decode methods without compressed sensing, the yardsticks a user would pick
//! instead of CS.
//!
//! Both read a capture's measurements exactly as the CS decoder does (the firmware's mask,
//! raw format and defect list: saturated, defective and non-finite samples are not
//! measurements) and return the light field `(U, V, S, T, B)`.
//!
//! - [`interpolate`]: per pixel, the spectrum interpolated linearly in band index between
//!   the bands that pixel measured, held constant beyond the first and last. At one
//!   snapshot a pixel measures one band, so its spectrum is flat: what a camera without
//!   any spatial reasoning would give.
//! - [`demosaic`]: each band estimated from the pixels that measured it nearby, all views
//!   of the lenslets within [`DemosaicConfig::radius`] lenslets weighted by a Gaussian of
//!   the lenslet distance; the estimate is then matched to each pixel's own measurements
//!   (scaled by the ratio of the pixel's measured values to the estimate at those bands,
//!   the colour-ratio rule of classic demosaicking, limited to
//!   [`DemosaicConfig::max_ratio`]) and the measured bands keep their measured values.
//!
//! - [`ppid`]: the published multispectral demosaicking method of Mihoubi et al. (2017),
//!   by the pseudo-panchromatic image, adapted to a random filter array spread over views.
//!
//! Every baseline's output is clamped to the sensor's physical range, as the CS decode's
//! is: `0` (no light) to the brightest value a pixel can measure in normalised units
//! ([`slf_firmware::RawFormat::range`]).
//!
//! A pixel with no measurement (all its samples invalid) takes, in [`interpolate`], the mean
//! spectrum of the measured pixels of its lenslet and the lenslets around it, and in
//! [`demosaic`] the neighbourhood's estimate; the report counts them.

use anyhow::{Result, ensure};
use rayon::prelude::*;

use crate::io::capture::Capture;
use crate::io::lightfield::LightField;

/// The neighbourhood demosaic's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DemosaicConfig {
    /// Lenslets either side that contribute to a band's estimate.
    pub radius: usize,
    /// Standard deviation of the Gaussian weight, in lenslets.
    pub sigma: f32,
    /// Largest factor (and smallest, as its inverse) by which the match to a pixel's own
    /// measurements scales the neighbourhood's spectrum.
    pub max_ratio: f32,
}

impl Default for DemosaicConfig {
    /// Radius 2 (5 x 5 lenslets, 625 samples at 5 x 5 views: about 48 a band at one
    /// snapshot), sigma 1 lenslet, ratios within 1/4..4.
    fn default() -> Self {
        Self { radius: 2, sigma: 1.0, max_ratio: 4.0 }
    }
}

/// A baseline decode method, by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Baseline {
    /// [`interpolate`].
    Interpolate,
    /// [`demosaic`] with [`DemosaicConfig::default`].
    Demosaic,
    /// [`ppid`] with [`PpidConfig::default`].
    Ppid,
}

impl Baseline {
    /// Every baseline, weakest first.
    pub const ALL: [Baseline; 3] = [Baseline::Interpolate, Baseline::Demosaic, Baseline::Ppid];

    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Baseline::Interpolate => "baseline: per-pixel interpolation",
            Baseline::Demosaic => "baseline: neighbourhood demosaic",
            Baseline::Ppid => "baseline: PPID (Mihoubi et al. 2017)",
        }
    }

    /// Decodes `capture` with this baseline.
    ///
    /// # Errors
    /// As [`interpolate`] and [`demosaic`].
    pub fn run(self, capture: &Capture) -> Result<(LightField, BaselineReport)> {
        match self {
            Baseline::Interpolate => interpolate(capture),
            Baseline::Demosaic => demosaic(capture, &DemosaicConfig::default()),
            Baseline::Ppid => ppid(capture, &PpidConfig::default()),
        }
    }
}

/// What a baseline did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BaselineReport {
    /// Sensor positions (lenslet x view) with at least one measurement.
    pub measured: usize,
    /// Sensor positions with none, filled from their neighbourhood.
    pub filled: usize,
    /// Wall time, seconds.
    pub seconds: f64,
}

/// Clamps every value to the sensor's physical range ([`slf_firmware::RawFormat::range`]):
/// the output contract of every decode method, the one the CS decoder keeps per patch. A
/// colour ratio or PPID's high-pass can push a value past what the sensor could have
/// recorded, and a measurement under the black level is below no light.
fn clamp_to_sensor(capture: &Capture, lf: &mut LightField) {
    let (lo, hi) = capture.raw_format().range();
    lf.data.iter_mut().for_each(|v| *v = v.clamp(lo, hi));
}

/// Every sensor position's valid measurements as `(band, value)`, in snapshot order,
/// indexed `(row * cols + col) * k + j`; `None` where a sample is not a measurement.
struct Samples {
    cols: usize,
    k: usize,
    bands: usize,
    views: (usize, usize),
    lenslets: (usize, usize),
    values: Vec<Option<(u8, f32)>>,
}

impl Samples {
    fn read(capture: &Capture) -> Result<Self> {
        let mask = capture.mask()?;
        let raw = capture.raw_format();
        let defects = capture.defects();
        let (rows, cols) = capture.frame_size();
        let k = capture.frames.len();
        let d = &capture.description;
        let mut values = vec![None; rows * cols * k];
        values.par_chunks_mut(cols * k).enumerate().for_each(|(row, out)| {
            for col in 0..cols {
                let bands = mask.bands_at(row, col);
                if defects.contains(row, col) {
                    continue;
                }
                for (j, (&band, frame)) in bands.iter().zip(&capture.frames).enumerate() {
                    if let Ok(v) = raw.classify(f32::from(frame[row * cols + col])) {
                        out[col * k + j] = Some((band, v));
                    }
                }
            }
        });
        Ok(Self {
            cols,
            k,
            bands: d.bands_nm.len(),
            views: (d.views[0], d.views[1]),
            lenslets: (d.lenslets[0], d.lenslets[1]),
            values,
        })
    }

    fn at(&self, row: usize, col: usize) -> &[Option<(u8, f32)>] {
        let i = (row * self.cols + col) * self.k;
        &self.values[i..i + self.k]
    }

    /// The sensor pixel of lenslet `(s, t)`, view `(u, v)`.
    fn pixel(&self, s: usize, t: usize, u: usize, v: usize) -> (usize, usize) {
        (s * self.views.0 + u, t * self.views.1 + v)
    }

    /// Every sensor position in the light field's order `(u, v, s, t)`: its index in that
    /// order (its spectrum starts at `index * bands` in the light field's data), its
    /// lenslet `(s, t)` and its valid measurements.
    fn positions(&self) -> impl Iterator<Item = (usize, (usize, usize), Vec<(u8, f32)>)> + '_ {
        let (vv, (ls, lt)) = (self.views.1, self.lenslets);
        (0..self.views.0 * vv * ls * lt).map(move |i| {
            let (uv, st) = (i / (ls * lt), i % (ls * lt));
            let (u, v, s, t) = (uv / vv, uv % vv, st / lt, st % lt);
            let (row, col) = self.pixel(s, t, u, v);
            (i, (s, t), self.at(row, col).iter().flatten().copied().collect())
        })
    }

    fn empty_field(&self) -> LightField {
        LightField::zeros(self.views, self.lenslets.0, self.lenslets.1, self.bands)
    }
}

/// The spectrum through `(band, value)` points (distinct bands, any order): linear in band
/// index between them, constant beyond. `None` without a point.
fn through(points: &mut [(u8, f32)], out: &mut [f32]) -> Option<()> {
    points.sort_by_key(|p| p.0);
    let (&first, &last) = (points.first()?, points.last()?);
    for (b, o) in out.iter_mut().enumerate() {
        let b8 = b as u8;
        *o = if b8 <= first.0 {
            first.1
        } else if b8 >= last.0 {
            last.1
        } else {
            let i = points.partition_point(|p| p.0 <= b8);
            let (lo, hi) = (points[i - 1], points[i]);
            let t = f32::from(b8 - lo.0) / f32::from(hi.0 - lo.0);
            lo.1 + t * (hi.1 - lo.1)
        };
    }
    Some(())
}

/// Fills positions without a measurement (`missing[i]`, `i` over `(u, v, s, t)` pixel
/// order of `lf`) with the mean spectrum of the measured ones in the 3 x 3 lenslets around.
fn fill(lf: &mut LightField, missing: &[bool]) {
    let (vu, vv) = lf.views;
    let (rows, cols, bands) = (lf.rows, lf.cols, lf.bands);
    let position = |u: usize, v: usize, s: usize, t: usize| ((u * vv + v) * rows + s) * cols + t;
    let mut filled = lf.data.clone();
    for u in 0..vu {
        for v in 0..vv {
            for s in 0..rows {
                for t in 0..cols {
                    if !missing[position(u, v, s, t)] {
                        continue;
                    }
                    let mut sum = vec![0.0f32; bands];
                    let mut n = 0u32;
                    for ss in s.saturating_sub(1)..(s + 2).min(rows) {
                        for tt in t.saturating_sub(1)..(t + 2).min(cols) {
                            for uu in 0..vu {
                                for vv2 in 0..vv {
                                    if !missing[position(uu, vv2, ss, tt)] {
                                        n += 1;
                                        for (a, &x) in sum.iter_mut().zip(lf.spectrum(uu, vv2, ss, tt)) {
                                            *a += x;
                                        }
                                    }
                                }
                            }
                        }
                    }
                    let at = lf.index(u, v, s, t, 0);
                    for (o, a) in filled[at..at + bands].iter_mut().zip(&sum) {
                        *o = if n > 0 { a / n as f32 } else { 0.0 };
                    }
                }
            }
        }
    }
    lf.data = filled;
}

/// Per lenslet, each band's Gaussian-weighted mean over the measurements of the lenslets
/// within `radius` (all views); a band no neighbour measured takes the interpolation of
/// the lenslet's other band estimates.
fn neighbourhood(samples: &Samples, radius: usize, sigma: f32, capture: &Capture) -> Result<Vec<Vec<f32>>> {
    let (ls, lt) = samples.lenslets;
    let nb = samples.bands;
    // Per lenslet and band: the sum and count of its views' measurements of that band.
    let mut sum = vec![0.0f32; ls * lt * nb];
    let mut count = vec![0.0f32; ls * lt * nb];
    for (_, (s, t), own) in samples.positions() {
        for (b, x) in own {
            let i = (s * lt + t) * nb + usize::from(b);
            sum[i] += x;
            count[i] += 1.0;
        }
    }
    ensure!(
        count.iter().any(|&c| c > 0.0),
        "{}: no pixel holds a measurement (all saturated or defective)",
        capture.source()
    );
    let r = radius as isize;
    let weight = |d2: f32| (-d2 / (2.0 * sigma * sigma)).exp();
    let estimate: Vec<Vec<f32>> = (0..ls * lt)
        .into_par_iter()
        .map(|st| {
            let (s, t) = ((st / lt) as isize, (st % lt) as isize);
            let (mut num, mut den) = (vec![0.0f32; nb], vec![0.0f32; nb]);
            for ds in -r..=r {
                for dt in -r..=r {
                    let (ss, tt) = (s + ds, t + dt);
                    if ss < 0 || tt < 0 || ss >= ls as isize || tt >= lt as isize {
                        continue;
                    }
                    let w = weight((ds * ds + dt * dt) as f32);
                    let i = (ss as usize * lt + tt as usize) * nb;
                    for b in 0..nb {
                        num[b] += w * sum[i + b];
                        den[b] += w * count[i + b];
                    }
                }
            }
            let mut points: Vec<(u8, f32)> =
                (0..nb).filter(|&b| den[b] > 0.0).map(|b| (b as u8, num[b] / den[b])).collect();
            let mut out = vec![0.0f32; nb];
            // Within the known bands, interpolation equals the estimates themselves.
            let _ = through(&mut points, &mut out);
            for b in 0..nb {
                if den[b] > 0.0 {
                    out[b] = num[b] / den[b];
                }
            }
            out
        })
        .collect();
    Ok(estimate)
}

/// Per-pixel spectral interpolation between the measured bands (see the module docs).
///
/// # Errors
/// A capture whose mask cannot be built, or one without a single measurement.
pub fn interpolate(capture: &Capture) -> Result<(LightField, BaselineReport)> {
    let start = std::time::Instant::now();
    let samples = Samples::read(capture)?;
    let mut lf = samples.empty_field();
    let nb = samples.bands;
    let mut missing = vec![false; lf.data.len() / nb];
    let mut report = BaselineReport::default();
    for (i, _, mut points) in samples.positions() {
        if through(&mut points, &mut lf.data[i * nb..(i + 1) * nb]).is_some() {
            report.measured += 1;
        } else {
            missing[i] = true;
            report.filled += 1;
        }
    }
    ensure!(report.measured > 0, "{}: no pixel holds a measurement (all saturated or defective)", capture.source());
    fill(&mut lf, &missing);
    clamp_to_sensor(capture, &mut lf);
    report.seconds = start.elapsed().as_secs_f64();
    Ok((lf, report))
}

/// Neighbourhood demosaic matched to each pixel's own measurements (see the module docs).
///
/// # Errors
/// A capture whose mask cannot be built, one without a single measurement, or settings out
/// of range.
pub fn demosaic(capture: &Capture, cfg: &DemosaicConfig) -> Result<(LightField, BaselineReport)> {
    ensure!(cfg.sigma.is_finite() && cfg.sigma > 0.0, "demosaic sigma {} must be above 0", cfg.sigma);
    ensure!(cfg.max_ratio.is_finite() && cfg.max_ratio >= 1.0, "demosaic max_ratio {} must be >= 1", cfg.max_ratio);
    let start = std::time::Instant::now();
    let samples = Samples::read(capture)?;
    let estimate = neighbourhood(&samples, cfg.radius, cfg.sigma, capture)?;
    let lt = samples.lenslets.1;
    let nb = samples.bands;
    let mut lf = samples.empty_field();
    let mut report = BaselineReport::default();
    for (i, (s, t), own) in samples.positions() {
        let e = &estimate[s * lt + t];
        let at = i * nb;
        if own.is_empty() {
            // No measurement here: the neighbourhood's spectrum as it is.
            report.filled += 1;
            lf.data[at..at + nb].copy_from_slice(e);
            continue;
        }
        report.measured += 1;
        let (mine, theirs): (f32, f32) =
            own.iter().fold((0.0, 0.0), |(a, b), &(band, x)| (a + x, b + e[usize::from(band)]));
        let ratio =
            if theirs > 1e-6 && mine > 0.0 { (mine / theirs).clamp(1.0 / cfg.max_ratio, cfg.max_ratio) } else { 1.0 };
        for (o, &x) in lf.data[at..at + nb].iter_mut().zip(e) {
            *o = x * ratio;
        }
        for &(band, x) in &own {
            lf.data[at + usize::from(band)] = x;
        }
    }
    clamp_to_sensor(capture, &mut lf);
    report.seconds = start.elapsed().as_secs_f64();
    Ok((lf, report))
}

/// A sensor position's lenslet `(s, t)` and valid measurements `(band, value)`.
type Position = ((usize, usize), Vec<(u8, f32)>);

/// The pseudo-panchromatic demosaic's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PpidConfig {
    /// Lenslets either side that contribute.
    pub radius: usize,
    /// Standard deviation of the Gaussian weight, in lenslets.
    pub sigma: f32,
    /// The edge-sensing weight is `1 / (epsilon + |P(p) - P(q)|)` (white = 1 units).
    pub epsilon: f32,
}

impl Default for PpidConfig {
    /// As the neighbourhood demosaic (radius 2, sigma 1 lenslet); epsilon 0.02.
    fn default() -> Self {
        Self { radius: 2, sigma: 1.0, epsilon: 0.02 }
    }
}

/// PPID: multispectral demosaicking by the pseudo-panchromatic image, after S. Mihoubi,
/// O. Losson, B. Mathon and L. Macaire, "Multispectral Demosaicing Using
/// Pseudo-Panchromatic Image", IEEE Transactions on Computational Imaging 3(4), 2017.
///
/// The method, as published for periodic filter arrays: (1) a pseudo-panchromatic image
/// (PPI, the mean over bands) is estimated by a low-pass of the raw mosaic, then sharpened
/// at each pixel by its own raw value plus the local difference between the PPI and the
/// raw values of the same band; (2) each band is the PPI plus the band's difference to the
/// PPI, interpolated from the pixels that measured it with edge-sensing weights (large
/// where the PPI is alike). Demosaicking in the difference domain keeps the edges the PPI
/// carries, which plain per-band interpolation blurs.
///
/// slf's filter array is random per pixel and spread over views, so two steps are adapted:
/// the low-pass is the band-balanced mean of the neighbourhood's per-band estimates (a
/// periodic array's averaging kernel balances the bands by construction; a random one does
/// not), and neighbours are all views of the lenslets within [`PpidConfig::radius`],
/// weighted by a Gaussian of the lenslet distance times the edge-sensing weight
/// `1 / (epsilon + |P(p) - P(q)|)`. Measured bands keep their measured values.
///
/// # Errors
/// A capture whose mask cannot be built, one without a single measurement, or settings out
/// of range.
pub fn ppid(capture: &Capture, cfg: &PpidConfig) -> Result<(LightField, BaselineReport)> {
    ensure!(cfg.sigma.is_finite() && cfg.sigma > 0.0, "ppid sigma {} must be above 0", cfg.sigma);
    ensure!(cfg.epsilon.is_finite() && cfg.epsilon > 0.0, "ppid epsilon {} must be above 0", cfg.epsilon);
    let start = std::time::Instant::now();
    let samples = Samples::read(capture)?;
    let estimate = neighbourhood(&samples, cfg.radius, cfg.sigma, capture)?;
    let (ls, lt) = samples.lenslets;
    let nb = samples.bands;
    let coarse: Vec<f32> = estimate.iter().map(|e| e.iter().sum::<f32>() / nb as f32).collect();
    // Every position's lenslet and measurements, and the positions of each lenslet.
    let positions: Vec<Position> = samples.positions().map(|(_, st, own)| (st, own)).collect();
    // The same, laid out lenslet by lenslet (each lenslet's positions in position order,
    // each position's measurements after another): the walk over a neighbourhood reads
    // memory in order. Read through each position's own allocation, a 128 x 128-lenslet
    // frame's PPID took 43 s on one thread, 2.4 times the CS decode.
    let mut slots: Vec<usize> = Vec::with_capacity(positions.len());
    let mut lenslet_start = vec![0usize; ls * lt + 1];
    {
        let mut by_lenslet: Vec<Vec<usize>> = vec![Vec::new(); ls * lt];
        for (i, ((s, t), _)) in positions.iter().enumerate() {
            by_lenslet[s * lt + t].push(i);
        }
        for (l, members) in by_lenslet.iter().enumerate() {
            slots.extend_from_slice(members);
            lenslet_start[l + 1] = slots.len();
        }
    }
    let mut taken: Vec<(u8, f32)> = Vec::new();
    let mut taken_start = Vec::with_capacity(slots.len() + 1);
    taken_start.push(0usize);
    for &q in &slots {
        taken.extend_from_slice(&positions[q].1);
        taken_start.push(taken.len());
    }
    let theirs = |j: usize| &taken[taken_start[j]..taken_start[j + 1]];
    let r = cfg.radius as isize;
    let gauss = |ds: isize, dt: isize| (-((ds * ds + dt * dt) as f32) / (2.0 * cfg.sigma * cfg.sigma)).exp();
    // Calls f(weight, neighbour's lenslet, neighbour's slot) for every position of the
    // lenslets around (s, t).
    let around = |s: usize, t: usize, f: &mut dyn FnMut(f32, usize, usize)| {
        for ds in -r..=r {
            for dt in -r..=r {
                let (ss, tt) = (s as isize + ds, t as isize + dt);
                if ss < 0 || tt < 0 || ss >= ls as isize || tt >= lt as isize {
                    continue;
                }
                let g = gauss(ds, dt);
                let l = ss as usize * lt + tt as usize;
                for j in lenslet_start[l]..lenslet_start[l + 1] {
                    f(g, l, j);
                }
            }
        }
    };
    // Step 1: the PPI at each position: its own values plus the local difference between
    // the coarse PPI and the raw values of the same band. That difference's sums depend on
    // the lenslet and the band alone (the neighbourhood is the lenslets around), so they
    // are summed once a lenslet for every band, in the order a position's walk adds them:
    // the same values, bit for bit, as summing them for each of a lenslet's 25 positions
    // (which took half of PPID's time).
    let differences: Vec<(Vec<f32>, Vec<f32>)> = (0..ls * lt)
        .into_par_iter()
        .map(|st| {
            let (mut num, mut den) = (vec![0.0f32; nb], vec![0.0f32; nb]);
            around(st / lt, st % lt, &mut |g, l, j| {
                for &(b, x) in theirs(j) {
                    num[usize::from(b)] += g * (coarse[l] - x);
                    den[usize::from(b)] += g;
                }
            });
            (num, den)
        })
        .collect();
    let ppi: Vec<f32> = (0..positions.len())
        .into_par_iter()
        .map(|p| {
            let ((s, t), own) = &positions[p];
            if own.is_empty() {
                return coarse[s * lt + t];
            }
            let (num, den) = &differences[s * lt + t];
            let sum: f32 = own
                .iter()
                .map(|&(b, x)| {
                    let b = usize::from(b);
                    x + if den[b] > 0.0 { num[b] / den[b] } else { coarse[s * lt + t] - estimate[s * lt + t][b] }
                })
                .sum();
            sum / own.len() as f32
        })
        .collect();
    let ppi_of_slot: Vec<f32> = slots.iter().map(|&q| ppi[q]).collect();
    // Step 2: each band is the PPI plus the band's difference to it, interpolated with
    // edge-sensing weights.
    let mut lf = samples.empty_field();
    lf.data.par_chunks_mut(nb).enumerate().for_each(|(p, out)| {
        let ((s, t), own) = &positions[p];
        let (mut num, mut den) = (vec![0.0f32; nb], vec![0.0f32; nb]);
        around(*s, *t, &mut |g, _, j| {
            let pq = ppi_of_slot[j];
            let w = g / (cfg.epsilon + (ppi[p] - pq).abs());
            for &(b, x) in theirs(j) {
                num[usize::from(b)] += w * (x - pq);
                den[usize::from(b)] += w;
            }
        });
        let e = &estimate[s * lt + t];
        for (b, o) in out.iter_mut().enumerate() {
            *o = ppi[p] + if den[b] > 0.0 { num[b] / den[b] } else { e[b] - coarse[s * lt + t] };
        }
        for &(b, x) in own {
            out[usize::from(b)] = x;
        }
    });
    let measured = positions.iter().filter(|(_, own)| !own.is_empty()).count();
    clamp_to_sensor(capture, &mut lf);
    let report =
        BaselineReport { measured, filled: positions.len() - measured, seconds: start.elapsed().as_secs_f64() };
    Ok((lf, report))
}

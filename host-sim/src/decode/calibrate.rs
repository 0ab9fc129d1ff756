//! A sensor's calibration from its calibration captures (issue 43, `slf calibrate`): dark
//! frames give each pixel's dark level, flat frames its flat (gain times vignetting), a band
//! sweep the filters' response matrix, and pixels whose dark level or flat no working pixel
//! has are listed as hot (behind a turned lenslet array, those whose centres lie outside the
//! array are listed apart, as outside it: unlit, not dead).
//!
//! Every capture is checked against the first (geometry, bands, levels, mask): a calibration
//! belongs to one camera. Exposures of a kind are averaged, and so are a capture's
//! snapshots (a pixel's dark level and flat do not depend on its filter: the flat's light
//! has equal energy in every band and a filter's response to it is its row's sum, 1 by the
//! response matrix's definition). The response matrix's entry `(f, b)` is the mean over the
//! working pixels behind filter `f` of what they record under band `b`'s light, dark level
//! removed and divided by their flat and the light's level.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};

use crate::decode::grid_fit::fit_grid;
use crate::io::calibration::{
    Calibration, CalibrationDescription, FORMAT, Sources, VERSION, check_response, read_response,
};
use crate::io::capture::{Capture, DESCRIPTION, Light};
use crate::io::output::Outputs;

/// A pixel whose dark level lies more than this fraction of the range (white - black) above
/// black is hot; so is one whose flat is below [`DEAD_FLAT`] or at saturation.
pub const HOT_DARK: f32 = 0.05;
/// The flat below which a pixel is dead (listed with the hot ones).
pub const DEAD_FLAT: f32 = 0.1;

/// What a calibration was made of, one line each, for the user.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub lines: Vec<String>,
}

/// `slf calibrate` (and `slf.calibrate`): the calibration of the capture folders `paths`
/// (a folder holding only capture folders, as `slf simulate --calibration-captures`
/// writes, stands for them, in name order), with measured filter curves from `response`
/// instead of a band sweep if given, written to the folder `output`.
///
/// # Errors
/// A path that is neither a capture folder nor a folder of them; a capture or curves file
/// that does not load; an output over an input; what [`calibrate`] refuses.
pub fn calibrate_folders(paths: &[PathBuf], output: &Path, response: Option<&Path>) -> Result<Report> {
    let mut folders = Vec::new();
    for dir in paths {
        if dir.join(DESCRIPTION).is_file() {
            folders.push(dir.clone());
        } else {
            let mut inner: Vec<PathBuf> = std::fs::read_dir(dir)
                .with_context(|| format!("{}: neither a capture folder nor a folder of them", dir.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_dir())
                .collect();
            // A subfolder that is no capture is named, not skipped without a word.
            if let Some(p) = inner.iter().find(|p| !p.join(DESCRIPTION).is_file()) {
                bail!("{}: no {DESCRIPTION}: a folder of calibration captures holds capture folders only", p.display());
            }
            ensure!(!inner.is_empty(), "{}: holds no capture folder", dir.display());
            inner.sort();
            folders.extend(inner);
        }
    }
    // Every capture is held while the calibration is made: the first's size times their
    // count is checked against the memory cap before the rest are read.
    let mut loaded: Vec<(String, Capture)> = Vec::with_capacity(folders.len());
    for (i, p) in folders.iter().enumerate() {
        let c = Capture::load(p)?;
        if i == 0 {
            let (rows, cols) = c.frame_size();
            let each = (c.frames.len() * rows * cols * 2) as u64;
            // The dark and flat sums and the hot pixels beside them, in f64: 17 bytes a pixel.
            let need = each * folders.len() as u64 + (rows * cols) as u64 * 17;
            crate::io::budget::check(
                need,
                &format!(
                    "{} calibration captures of {} frames of {rows} x {cols} pixels",
                    folders.len(),
                    c.frames.len()
                ),
                "fewer exposures",
            )?;
        }
        loaded.push((p.display().to_string(), c));
    }
    let mut outputs = Outputs::new();
    for (_, c) in &loaded {
        outputs = outputs.inputs(c.files(), "a calibration capture's file");
    }
    if let Some(path) = response {
        outputs = outputs.input(path, "the filter curves");
    }
    outputs.outputs(Calibration::files_in(output), "a file of the calibration -o").check_distinct()?;
    let bands = loaded.first().map_or(0, |(_, c)| c.description.bands_nm.len());
    let curves = response
        .map(|path| {
            read_response(path, bands)
                .and_then(|r| check_response(&r).map(|()| r).with_context(|| path.display().to_string()))
        })
        .transpose()?;
    let (calibration, report) = calibrate(&loaded, curves)?;
    calibration.save(output)?;
    Ok(report)
}

/// Calibrates the sensor behind `captures` (dark, flat and, unless `response` is given as
/// measured filter curves `[filter][band]`, one band capture per band at least).
///
/// # Errors
/// No capture, a scene among them, captures of different cameras (named), a kind missing,
/// a filter type no working pixel has.
pub fn calibrate(captures: &[(String, Capture)], response: Option<Vec<Vec<f32>>>) -> Result<(Calibration, Report)> {
    let Some((first_name, first)) = captures.first() else { bail!("no calibration capture given") };
    let d0 = &first.description;
    for (name, c) in captures {
        let d = &c.description;
        ensure!(!d.light.is_scene(), "{name}: a scene's capture (its light is not dark, flat or a band)");
        ensure!(
            d.lenslets == d0.lenslets
                && d.views == d0.views
                && d.bands_nm == d0.bands_nm
                && d.mask == d0.mask
                && d.black_level == d0.black_level
                && d.white_level == d0.white_level
                && d.lenslet_grid.map(|g| g.sensor) == d0.lenslet_grid.map(|g| g.sensor)
                && d.lenslet_grid.map(|g| g.offset) == d0.lenslet_grid.map(|g| g.offset),
            "{name}: another camera than {first_name}'s (lenslets, views, bands, mask, levels, sensor size or the \
             stated lenslet (0, 0) differ)"
        );
        // One sensor throughout: a folder holding another simulated sensor's captures
        // beside these once calibrated with rc 0 and cost the decode 5.5 dB.
        ensure!(
            d.simulated_sensor == d0.simulated_sensor,
            "{name}: another sensor than {first_name}'s (its simulated_sensor differs): calibrate each sensor's \
             captures apart"
        );
    }
    let (rows, cols) = first.frame_size();
    let bands = d0.bands_nm.len();
    let (black, range) = (d0.black_level, d0.white_level - d0.black_level);
    let of = |want: fn(&Light) -> bool| captures.iter().filter(move |(_, c)| want(&c.description.light));
    let darks: Vec<_> = of(|l| *l == Light::Dark).collect();
    let flats: Vec<_> = of(|l| matches!(l, Light::Flat { .. })).collect();
    ensure!(!darks.is_empty(), "no dark capture (light \"dark\") among the {} given", captures.len());
    ensure!(!flats.is_empty(), "no flat capture (light {{\"flat\": ...}}) among the {} given", captures.len());

    // Dark levels: the mean of every dark frame.
    let mut dark = vec![0.0f64; rows * cols];
    let mut n = 0usize;
    for (_, c) in &darks {
        for f in c.frames.held((rows, cols))?.iter() {
            for (d, &x) in dark.iter_mut().zip(f) {
                *d += f64::from(x);
            }
            n += 1;
        }
    }
    let dark: Vec<f32> = dark.iter().map(|&d| (d / n as f64) as f32).collect();

    // Flats: light above the dark level over the light's, in units of white.
    let saturation = d0.saturation_level;
    let mut flat = vec![0.0f64; rows * cols];
    let mut saturated = vec![false; rows * cols];
    let mut n = 0usize;
    for (_, c) in &flats {
        let Light::Flat { level } = c.description.light else { continue };
        for f in c.frames.held((rows, cols))?.iter() {
            for (p, &x) in f.iter().enumerate() {
                saturated[p] |= f32::from(x) >= saturation;
                flat[p] += f64::from((f32::from(x) - dark[p]) / (range * level));
            }
            n += 1;
        }
    }
    let flat: Vec<f32> = flat.iter().map(|&v| (v / n as f64).max(0.0) as f32).collect();

    // Hot and dead pixels, and the ones the captures list as defective.
    let mut bad: Vec<bool> =
        (0..rows * cols).map(|p| dark[p] - black > HOT_DARK * range || flat[p] < DEAD_FLAT || saturated[p]).collect();
    for (_, c) in captures {
        for &[r, col] in &c.description.defective_pixels {
            bad[r as usize * cols + col as usize] = true;
        }
    }

    // Behind a lenslet grid, the grid from the flats, hot pixels replaced by their working
    // neighbours' mean.
    let [u_n, v_n] = d0.views;
    let fit = match &d0.lenslet_grid {
        None => None,
        Some(stated) => {
            let mended = mend(&flat, &bad, (rows, cols));
            Some(fit_grid(&mended, (rows, cols), d0.lenslets, d0.views, stated.offset).context("the lenslet grid")?)
        }
    };
    // Vignetting per view: the mean flat of the working pixels at each view (behind a
    // grid, the view cell a pixel's centre lies in as the decode maps it, the firmware's
    // `LensletGrid::view_of`; pixels off the light field left out).
    let mapping = fit.as_ref().map(|f| f.grid.firmware(d0.views)).transpose()?;
    // A turned array leaves pixels at the sensor's edges that no lenslet of the array
    // lights: dark in the flats, but not dead. They are listed apart (no patch reads them).
    let in_array = |p: usize| match &mapping {
        None => true,
        Some(g) => g.view_of(p / cols, p % cols).is_some_and(|((s, t), _)| s < d0.lenslets[0] && t < d0.lenslets[1]),
    };
    let at = |p: usize| [(p / cols) as u32, (p % cols) as u32];
    let hot_pixels: Vec<[u32; 2]> = (0..rows * cols).filter(|&p| bad[p] && in_array(p)).map(at).collect();
    let outside_pixels: Vec<[u32; 2]> = (0..rows * cols).filter(|&p| bad[p] && !in_array(p)).map(at).collect();
    let mut sums = vec![(0.0f64, 0usize); u_n * v_n];
    for p in (0..rows * cols).filter(|&p| !bad[p]) {
        let (u, v) = match &mapping {
            None => ((p / cols) % u_n, (p % cols) % v_n),
            Some(g) => match g.view_of(p / cols, p % cols) {
                Some(((s, t), uv)) if s < d0.lenslets[0] && t < d0.lenslets[1] => uv,
                _ => continue,
            },
        };
        let s = &mut sums[u * v_n + v];
        *s = (s.0 + f64::from(flat[p]), s.1 + 1);
    }
    ensure!(sums.iter().all(|s| s.1 > 0), "a view with no working pixel: the flats are dark or saturated");
    let means: Vec<f64> = sums.iter().map(|s| s.0 / s.1 as f64).collect();
    let top = means.iter().fold(0.0f64, |m, &x| m.max(x));
    ensure!(top > 0.0, "the flats record no light");
    let vignetting: Vec<Vec<f32>> =
        (0..u_n).map(|u| (0..v_n).map(|v| (means[u * v_n + v] / top) as f32).collect()).collect();

    // The response matrix: measured curves as given, or the band sweep.
    let band_count = of(|l| matches!(l, Light::Band { .. })).count();
    let response = match response {
        Some(r) => r,
        None => {
            let mut seen = BTreeMap::new();
            let mut sum = vec![0.0f64; bands * bands];
            let mut count = vec![0usize; bands * bands];
            // Saturated values would enter the mean at the top code (a band's saturated
            // captures once gave its column 1.39 behind every filter); each band's are
            // counted, and a sweep with any is refused.
            let mut clipped: BTreeMap<usize, (usize, usize, &str)> = BTreeMap::new();
            for (name, c) in of(|l| matches!(l, Light::Band { .. })) {
                let Light::Band { band, level } = c.description.light else { continue };
                let b = usize::from(band);
                *seen.entry(b).or_insert(0usize) += 1;
                let mask = c.mask()?;
                let entry = clipped.entry(b).or_insert((0, 0, name));
                for (j, f) in c.frames.held((rows, cols))?.iter().enumerate() {
                    for (p, &x) in f.iter().enumerate() {
                        if bad[p] {
                            continue;
                        }
                        entry.1 += 1;
                        if f32::from(x) >= saturation {
                            entry.0 += 1;
                            if entry.0 == 1 {
                                entry.2 = name;
                            }
                            continue;
                        }
                        let filter = usize::from(mask.bands_at(p / cols, p % cols)[j]);
                        sum[filter * bands + b] += f64::from((f32::from(x) - dark[p]) / (flat[p] * range * level));
                        count[filter * bands + b] += 1;
                    }
                }
            }
            if let Some((b, (n, of_all, name))) = clipped.iter().find(|(_, e)| e.0 > 0) {
                bail!(
                    "{name}: {n} of {of_all} working pixels' values under band {b}'s light ({} nm) are saturated: a \
                     band capture must not saturate (record it at a lower level)",
                    d0.bands_nm[*b]
                );
            }
            if let Some(b) = (0..bands).find(|b| !seen.contains_key(b)) {
                bail!(
                    "no capture under band {b}'s light ({} nm): a sweep needs one per band, or --response \
                     FILE with measured filter curves",
                    d0.bands_nm[b]
                );
            }
            if let Some(f) = (0..bands).find(|&f| count[f * bands] == 0) {
                bail!("filter type {f} ({} nm) has no working pixel in the sweep", d0.bands_nm[f]);
            }
            let r: Vec<Vec<f32>> = (0..bands)
                .map(|f| (0..bands).map(|b| (sum[f * bands + b] / count[f * bands + b] as f64) as f32).collect())
                .collect();
            // The sweep's labels against its frames: band b's light is seen most by filter
            // b (labels rotated by one once calibrated at 16.8 dB with rc 0).
            for (b, band_nm) in d0.bands_nm.iter().enumerate() {
                let most = (0..bands).max_by(|&f, &g| r[f][b].total_cmp(&r[g][b])).unwrap_or(b);
                if most != b {
                    let name = clipped.get(&b).map_or("", |e| e.2);
                    bail!(
                        "{name}: the captures labelled band {b} ({} nm) are seen most by filter {most} ({} nm), not \
                         by filter {b}: is the sweep mislabelled?",
                        band_nm,
                        d0.bands_nm[most]
                    );
                }
            }
            r
        }
    };
    // What a decode will refuse, refused now: a calibration is made to be decoded with.
    check_response(&response).context("the calibration's response matrix would not decode")?;

    let description = CalibrationDescription {
        format: FORMAT.into(),
        version: VERSION,
        lenslets: d0.lenslets,
        views: d0.views,
        bands_nm: d0.bands_nm.clone(),
        black_level: d0.black_level,
        white_level: d0.white_level,
        response,
        vignetting,
        hot_pixels,
        outside_pixels,
        sources: Sources { dark: darks.len(), flat: flats.len(), band: band_count },
        lenslet_grid: fit.map(|f| f.grid),
        files: None,
    };
    let mut report = Report {
        lines: vec![
            format!(
                "calibration: {} dark, {} flat and {} band captures of {} x {} lenslets, {} x {} views",
                darks.len(),
                flats.len(),
                band_count,
                d0.lenslets[0],
                d0.lenslets[1],
                u_n,
                v_n
            ),
            format!(
                "{} hot, dead or defective pixels of {}{}; vignetting: the darkest view gets {:.3} of the brightest's",
                description.hot_pixels.len(),
                rows * cols,
                match description.outside_pixels.len() {
                    0 => String::new(),
                    n => format!(" ({n} more outside the lenslet array: no lenslet lights them, no patch reads them)"),
                },
                description.vignetting.iter().flatten().fold(1.0f32, |m, &x| m.min(x))
            ),
        ],
    };
    if let Some(f) = &fit {
        let g = &f.grid;
        report.lines.push(format!(
            "lenslet grid: rotation {:.4} degrees, pitch {:.4} x {:.4} px, lenslet (0, 0) at ({:.3}, {:.3}) (the \
             micro-image nearest the captures' stated ({:.3}, {:.3})); {} micro-image centres within {:.3} px RMS ({} \
             left out)",
            g.rotation_deg,
            g.pitch[0],
            g.pitch[1],
            g.offset[0],
            g.offset[1],
            g.indexed_at.unwrap_or(g.offset)[0],
            g.indexed_at.unwrap_or(g.offset)[1],
            f.centres,
            g.centres_rms_px.unwrap_or(0.0),
            f.outliers
        ));
    }
    Ok((Calibration::new(description, dark, flat)?, report))
}

/// `flat` with each of its `bad` pixels the mean of its working 8 neighbours (1 where it
/// has none): the grid is found from the flat's shape, which a hot pixel would bend.
fn mend(flat: &[f32], bad: &[bool], (rows, cols): (usize, usize)) -> Vec<f32> {
    let mut out = flat.to_vec();
    for p in (0..rows * cols).filter(|&p| bad[p]) {
        let (r, c) = (p / cols, p % cols);
        let (mut sum, mut n) = (0.0f32, 0u32);
        for rr in r.saturating_sub(1)..=(r + 1).min(rows - 1) {
            for cc in c.saturating_sub(1)..=(c + 1).min(cols - 1) {
                if !bad[rr * cols + cc] {
                    sum += flat[rr * cols + cc];
                    n += 1;
                }
            }
        }
        out[p] = if n > 0 { sum / n as f32 } else { 1.0 };
    }
    out
}

/// The inverse of `cal`'s response matrix, row-major `[band][filter]`.
///
/// # Errors
/// A response matrix [`check_response`] refuses.
pub fn unmixing(cal: &CalibrationDescription) -> Result<Vec<f32>> {
    let b = cal.bands_nm.len();
    check_response(&cal.response)?;
    let r = nalgebra::DMatrix::from_fn(b, b, |f, band| f64::from(cal.response[f][band]));
    let inv = r.try_inverse().ok_or_else(|| anyhow::anyhow!("the response matrix is singular"))?;
    Ok((0..b).flat_map(|i| (0..b).map(move |j| (i, j))).map(|(i, j)| inv[(i, j)] as f32).collect())
}

/// Every spectrum of `values` (`bands` values each: what the one-hot decode recovered, each
/// band as its filter saw it) unmixed by `inverse` ([`unmixing`]): the light the scene sent.
pub fn unmix(values: &mut [f32], bands: usize, inverse: &[f32]) {
    let b = bands;
    let mut out = vec![0.0f32; b];
    for z in values.chunks_exact_mut(b) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = inverse[i * b..(i + 1) * b].iter().zip(z.iter()).map(|(a, x)| a * x).sum();
        }
        z.copy_from_slice(&out);
    }
}

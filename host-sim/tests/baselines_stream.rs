//! The streamed baselines (a window of lenslet rows, sums per lenslet, lenslet-major rows)
//! against slow, obvious, whole-frame references written from the formulas in their docs:
//! every position's samples gathered first, every sum taken sample by sample in the light
//! field's own order. Different summation orders round differently, so the two agree to a
//! tolerance, not bit for bit; the frames are non-square and shorter than PPID's reach
//! (three radii) so a window's edges and a swapped axis would show.

use slf_host::decode::baselines::{Baseline, DemosaicConfig, PpidConfig, demosaic, interpolate, ppid};
use slf_host::io::capture::Capture;
use slf_host::io::capture::{MaskDescription, MaskSource};
use slf_host::io::lightfield::LightField;
use slf_host::sim::camera::{CameraConfig, simulate};
use slf_host::sim::scene::{SceneSize, named};

/// Largest difference allowed, in white = 1 units: f32 sums of tens of terms taken in
/// another order, through PPID's edge weights (up to 1 / epsilon = 50 times a difference).
const TOLERANCE: f32 = 2e-4;

/// A capture's samples and shape as the references read them.
struct Frame {
    views: (usize, usize),
    lenslets: (usize, usize),
    bands: usize,
    /// Valid `(band, value)` samples of position `(u, v, s, t)`, in snapshot order.
    samples: Vec<Vec<(u8, f32)>>,
    range: (f32, f32),
}

impl Frame {
    fn of(cap: &Capture) -> Self {
        let d = &cap.description;
        let (views, lenslets) = ((d.views[0], d.views[1]), (d.lenslets[0], d.lenslets[1]));
        let (mask, raw, defects, cols) = (cap.mask().unwrap(), cap.raw_format(), cap.defects(), cap.frame_size().1);
        let frames = cap.held_frames().unwrap();
        let mut samples = Vec::new();
        for u in 0..views.0 {
            for v in 0..views.1 {
                for s in 0..lenslets.0 {
                    for t in 0..lenslets.1 {
                        let (row, col) = (s * views.0 + u, t * views.1 + v);
                        let mut here = Vec::new();
                        if !defects.contains(row, col) {
                            for (&b, frame) in mask.bands_at(row, col).iter().zip(frames.iter()) {
                                if let Ok(x) = raw.classify(f32::from(frame[row * cols + col])) {
                                    here.push((b, x));
                                }
                            }
                        }
                        samples.push(here);
                    }
                }
            }
        }
        Self { views, lenslets, bands: d.bands_nm.len(), samples, range: raw.range() }
    }

    fn at(&self, u: usize, v: usize, s: usize, t: usize) -> &[(u8, f32)] {
        &self.samples[((u * self.views.1 + v) * self.lenslets.0 + s) * self.lenslets.1 + t]
    }

    /// Lenslets within `r` of `(s, t)` on the frame, with their lenslet offsets.
    fn near(&self, s: usize, t: usize, r: usize) -> Vec<(usize, usize, f32)> {
        let mut out = Vec::new();
        for ss in s.saturating_sub(r)..=(s + r).min(self.lenslets.0 - 1) {
            for tt in t.saturating_sub(r)..=(t + r).min(self.lenslets.1 - 1) {
                let (ds, dt) = (ss as f32 - s as f32, tt as f32 - t as f32);
                out.push((ss, tt, ds * ds + dt * dt));
            }
        }
        out
    }

    fn views(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.views.0).flat_map(move |u| (0..self.views.1).map(move |v| (u, v)))
    }

    /// The light field `f(u, v, s, t)` gives each spectrum of, clamped to the sensor's range.
    fn field(&self, f: impl Fn(usize, usize, usize, usize) -> Vec<f32>) -> LightField {
        let mut lf = LightField::zeros(self.views, self.lenslets.0, self.lenslets.1, self.bands);
        for (u, v) in self.views() {
            for s in 0..self.lenslets.0 {
                for t in 0..self.lenslets.1 {
                    let at = lf.index(u, v, s, t, 0);
                    for (o, x) in lf.data[at..at + self.bands].iter_mut().zip(f(u, v, s, t)) {
                        *o = x.clamp(self.range.0, self.range.1);
                    }
                }
            }
        }
        lf
    }

    /// Each band's Gaussian-weighted mean over the samples of every view of the lenslets
    /// within `r`; bands no sample reached interpolated between the others.
    fn estimate(&self, s: usize, t: usize, r: usize, sigma: f32) -> Vec<f32> {
        let (mut num, mut den) = (vec![0.0f32; self.bands], vec![0.0f32; self.bands]);
        for (ss, tt, d2) in self.near(s, t, r) {
            let w = (-d2 / (2.0 * sigma * sigma)).exp();
            for (u, v) in self.views() {
                for &(b, x) in self.at(u, v, ss, tt) {
                    num[usize::from(b)] += w * x;
                    den[usize::from(b)] += w;
                }
            }
        }
        let known: Vec<(u8, f32)> =
            (0..self.bands).filter(|&b| den[b] > 0.0).map(|b| (b as u8, num[b] / den[b])).collect();
        line_through(&known, self.bands)
    }
}

/// The spectrum through `points` (increasing bands): linear between, flat beyond; zeros
/// without a point.
fn line_through(points: &[(u8, f32)], bands: usize) -> Vec<f32> {
    (0..bands)
        .map(|b| {
            let b = b as f32;
            let below = points.iter().rev().find(|p| f32::from(p.0) <= b);
            let above = points.iter().find(|p| f32::from(p.0) >= b);
            match (below, above) {
                (Some(lo), Some(hi)) if hi.0 > lo.0 => {
                    lo.1 + (b - f32::from(lo.0)) / f32::from(hi.0 - lo.0) * (hi.1 - lo.1)
                }
                (Some(p), _) | (None, Some(p)) => p.1,
                (None, None) => 0.0,
            }
        })
        .collect()
}

fn sorted(samples: &[(u8, f32)]) -> Vec<(u8, f32)> {
    let mut p = samples.to_vec();
    p.sort_by_key(|p| p.0);
    p
}

fn interpolate_reference(f: &Frame) -> LightField {
    let own = |u, v, s, t| line_through(&sorted(f.at(u, v, s, t)), f.bands);
    f.field(|u, v, s, t| {
        if !f.at(u, v, s, t).is_empty() {
            return own(u, v, s, t);
        }
        let (mut sum, mut n) = (vec![0.0f32; f.bands], 0.0f32);
        for (ss, tt, _) in f.near(s, t, 1) {
            for (uu, vv) in f.views() {
                if !f.at(uu, vv, ss, tt).is_empty() {
                    n += 1.0;
                    sum.iter_mut().zip(own(uu, vv, ss, tt)).for_each(|(a, x)| *a += x);
                }
            }
        }
        sum.iter().map(|a| if n > 0.0 { a / n } else { 0.0 }).collect()
    })
}

fn demosaic_reference(f: &Frame, cfg: &DemosaicConfig) -> LightField {
    f.field(|u, v, s, t| {
        let e = f.estimate(s, t, cfg.radius, cfg.sigma);
        let own = f.at(u, v, s, t);
        if own.is_empty() {
            return e;
        }
        let mine: f32 = own.iter().map(|p| p.1).sum();
        let theirs: f32 = own.iter().map(|p| e[usize::from(p.0)]).sum();
        let ratio =
            if theirs > 1e-6 && mine > 0.0 { (mine / theirs).clamp(1.0 / cfg.max_ratio, cfg.max_ratio) } else { 1.0 };
        let mut out: Vec<f32> = e.iter().map(|x| x * ratio).collect();
        own.iter().for_each(|&(b, x)| out[usize::from(b)] = x);
        out
    })
}

fn ppid_reference(f: &Frame, cfg: &PpidConfig) -> LightField {
    let (ls, lt) = f.lenslets;
    let gauss = |d2: f32| (-d2 / (2.0 * cfg.sigma * cfg.sigma)).exp();
    let estimates: Vec<Vec<f32>> = (0..ls * lt).map(|l| f.estimate(l / lt, l % lt, cfg.radius, cfg.sigma)).collect();
    let coarse: Vec<f32> = estimates.iter().map(|e| e.iter().sum::<f32>() / f.bands as f32).collect();
    // Step 1: each position's PPI, its samples plus the band's mean difference between
    // the coarse PPI and the samples of that band around.
    let ppi = |u: usize, v: usize, s: usize, t: usize| -> f32 {
        let own = f.at(u, v, s, t);
        if own.is_empty() {
            return coarse[s * lt + t];
        }
        let sum: f32 = own
            .iter()
            .map(|&(b, x)| {
                let (mut num, mut den) = (0.0f32, 0.0f32);
                for (ss, tt, d2) in f.near(s, t, cfg.radius) {
                    for (uu, vv) in f.views() {
                        for &(bb, xx) in f.at(uu, vv, ss, tt) {
                            if bb == b {
                                num += gauss(d2) * (coarse[ss * lt + tt] - xx);
                                den += gauss(d2);
                            }
                        }
                    }
                }
                x + if den > 0.0 { num / den } else { coarse[s * lt + t] - estimates[s * lt + t][usize::from(b)] }
            })
            .sum();
        sum / own.len() as f32
    };
    let ppis: Vec<f32> = f
        .views()
        .flat_map(|(u, v)| (0..ls * lt).map(move |l| (u, v, l)))
        .map(|(u, v, l)| ppi(u, v, l / lt, l % lt))
        .collect();
    let ppi_at = |u: usize, v: usize, s: usize, t: usize| ppis[((u * f.views.1 + v) * ls + s) * lt + t];
    // Step 2: each band the PPI plus its difference to the PPI, weighted by the Gaussian
    // and by 1 / (epsilon + |P(p) - P(q)|).
    f.field(|u, v, s, t| {
        let p = ppi_at(u, v, s, t);
        let (mut num, mut den) = (vec![0.0f32; f.bands], vec![0.0f32; f.bands]);
        for (ss, tt, d2) in f.near(s, t, cfg.radius) {
            for (uu, vv) in f.views() {
                let q = ppi_at(uu, vv, ss, tt);
                let w = gauss(d2) / (cfg.epsilon + (p - q).abs());
                for &(b, x) in f.at(uu, vv, ss, tt) {
                    num[usize::from(b)] += w * (x - q);
                    den[usize::from(b)] += w;
                }
            }
        }
        let (e, c) = (&estimates[s * lt + t], coarse[s * lt + t]);
        let mut out: Vec<f32> =
            (0..f.bands).map(|b| p + if den[b] > 0.0 { num[b] / den[b] } else { e[b] - c }).collect();
        f.at(u, v, s, t).iter().for_each(|&(b, x)| out[usize::from(b)] = x);
        out
    })
}

/// Captures with non-square frames, defects, saturation, several snapshots and masks.
fn captures() -> Vec<(&'static str, Capture)> {
    let render =
        |name: &str, views, rows, cols| named(name).unwrap().render(SceneSize { views: (views, views), rows, cols });
    let mut with_defects = CameraConfig::pixel(2, 3);
    with_defects.defect_fraction = 0.05;
    let lenslet = CameraConfig::pixel(3, 2).with_mask(MaskDescription::Lenslet(MaskSource {
        snapshots: Some(2),
        seed: Some(3),
        tile: None,
    }));
    vec![
        (
            "texture, pixel mask, k = 1, 17 x 11",
            simulate(&render("texture", 5, 17, 11), &CameraConfig::pixel(1, 1)).unwrap(),
        ),
        (
            "texture, 4 x 4 views, k = 3, defects, 9 x 14",
            simulate(&render("texture", 4, 9, 14), &with_defects).unwrap(),
        ),
        ("saturated, lenslet mask, k = 2, 12 x 7", simulate(&render("saturated", 5, 12, 7), &lenslet).unwrap()),
    ]
}

fn assert_close(what: &str, got: &LightField, want: &LightField) {
    assert_eq!((got.views, got.rows, got.cols, got.bands), (want.views, want.rows, want.cols, want.bands), "{what}");
    let worst = got.data.iter().zip(&want.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(worst <= TOLERANCE, "{what}: differs from the whole-frame reference by {worst}");
}

#[test]
fn the_streamed_baselines_are_the_whole_frame_formulas() {
    for (name, cap) in captures() {
        let f = Frame::of(&cap);
        assert_close(&format!("{name}: interpolate"), &interpolate(&cap).unwrap().0, &interpolate_reference(&f));
        for cfg in [
            DemosaicConfig::default(),
            DemosaicConfig { radius: 1, sigma: 0.7, max_ratio: 4.0 },
            DemosaicConfig { radius: 3, sigma: 2.0, max_ratio: 1.5 },
        ] {
            let got = demosaic(&cap, &cfg).unwrap().0;
            assert_close(&format!("{name}: demosaic {cfg:?}"), &got, &demosaic_reference(&f, &cfg));
        }
        for cfg in [
            PpidConfig::default(),
            PpidConfig { radius: 1, sigma: 0.7, epsilon: 0.02 },
            PpidConfig { radius: 3, sigma: 2.0, epsilon: 0.1 },
        ] {
            let got = ppid(&cap, &cfg).unwrap().0;
            assert_close(&format!("{name}: ppid {cfg:?}"), &got, &ppid_reference(&f, &cfg));
        }
    }
}

/// A sink that records the order of the rows put into it and fails at one.
struct Recorder {
    rows: Vec<u16>,
    fail_at: u16,
}

impl slf_host::io::rows::RowSink for Recorder {
    type Error = anyhow::Error;

    fn row(&mut self, y: u16, _first_col: u16, _row: &[f32]) -> anyhow::Result<()> {
        anyhow::ensure!(y != self.fail_at, "the sink is full at row {y}");
        self.rows.push(y);
        Ok(())
    }
}

#[test]
fn each_row_is_put_once_in_order_and_a_sink_error_ends_the_decode() {
    let (_, cap) = captures().swap_remove(0);
    for b in Baseline::ALL {
        let mut all = Recorder { rows: Vec::new(), fail_at: u16::MAX };
        b.stream(&cap, &mut all).unwrap();
        assert_eq!(all.rows, (0..17).collect::<Vec<_>>(), "{b:?}");
        let mut full = Recorder { rows: Vec::new(), fail_at: 4 };
        let e = b.stream(&cap, &mut full).unwrap_err();
        assert!(format!("{e:#}").contains("full at row 4"), "{b:?}: {e:#}");
        assert_eq!(full.rows, [0, 1, 2, 3], "{b:?}");
    }
}

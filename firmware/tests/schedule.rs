//! Trained schedules (issue 42): a scheduled solve against the same steps written out with
//! dense f64 matrices; the noise ball and half-pixel shears on the scheduled path; the blob
//! that carries the schedules (round trip, version 1 still read, every corruption refused);
//! an ensemble decodes with its blob's schedules, cold, seeded and sheared.

mod common;

use common::*;
use rand::Rng;
use slf_firmware::blob::{scheduled_blob_len, write_blob_scheduled};
use slf_firmware::disparity::HalfViews;
use slf_firmware::schedule::{Schedule, Schedules, Weights};
use slf_firmware::sl0::{solve_scheduled, solve_warm_scheduled};
use slf_firmware::*;

type W = Weights<PatchShape<3, 3, 2, 2, 4, 144>>;
type S = Schedule<PatchShape<3, 3, 2, 2, 4, 144>>;
const N: usize = 144;

fn weights() -> W {
    let mut w = W::ONES;
    (w.s[1], w.t[2], w.u[1], w.v[0], w.b[3], w.b[0]) = (1.5, 0.7, 2.0, 0.8, 3.0, 0.5);
    w
}

fn schedule() -> S {
    S::new(&[0.6, 0.3, 0.1, 0.05, 0.01, 0.002], &[1.2, 1.8, 0.9, 2.0, 1.5, 1.0], weights()).unwrap()
}

/// Patch, measured entries (about a third, every pixel at least one band).
fn problem(seed: u64) -> (Vec<f32>, Vec<bool>) {
    let mut r = rng(seed);
    let truth: Vec<f32> = (0..N).map(|i| 0.4 + 0.2 * ((i as f32) * 0.37).sin() + r.random_range(-0.05..0.05)).collect();
    let measured: Vec<bool> = (0..N).map(|i| i % 4 == (i / 4) % 4 || r.random_bool(0.15)).collect();
    (truth, measured)
}

fn workspace(truth: &[f32], measured: &[bool]) -> Box<Workspace<PatchShape<3, 3, 2, 2, 4, N>>> {
    let mut ws = Box::new(Workspace::<PatchShape<3, 3, 2, 2, 4, N>>::new());
    for (i, (&x, &k)) in truth.iter().zip(measured).enumerate() {
        if k {
            ws.measurements_mut().set(i, x).unwrap();
        }
    }
    ws
}

/// The steps from the definition, dense in f64: `S0 = K^T y0` (zeros unmeasured), `sigma_t =
/// max(f_t max|S0|, sigma_min)`, `s <- s - mu s exp(-w s^2 / (2 sigma^2))`, then
/// `x = K s`, measured entries set to `y`, `s = K^T x`; the patch is `K s` with `y` put back.
fn reference(dict: &Dictionary<PatchShape<3, 3, 2, 2, 4, 144>>, s: &S, truth: &[f32], measured: &[bool]) -> Vec<f64> {
    let (k, n) = dense_kronecker(dict.synthesis());
    let apply_t = |x: &[f64]| -> Vec<f64> { (0..n).map(|j| (0..n).map(|i| k[i * n + j] * x[i]).sum()).collect() };
    let apply = |c: &[f64]| -> Vec<f64> { (0..n).map(|i| (0..n).map(|j| k[i * n + j] * c[j]).sum()).collect() };
    let y: Vec<f64> = truth.iter().zip(measured).map(|(&x, &m)| if m { f64::from(x) } else { 0.0 }).collect();
    let mut c = apply_t(&y);
    let sigma0 = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for (&f, &mu) in s.sigma().iter().zip(s.mu()) {
        let sigma = (f64::from(f) * sigma0).max(f64::from(Sl0Config::DEFAULT.sigma_min));
        for (i, c) in c.iter_mut().enumerate() {
            let w = f64::from(s.weights().at(PatchShape::<3, 3, 2, 2, 4, N>::coordinates(i)));
            *c -= f64::from(mu) * *c * (-w * *c * *c / (2.0 * sigma * sigma)).exp();
        }
        let mut x = apply(&c);
        x.iter_mut().zip(&y).zip(measured).filter(|(_, m)| **m).for_each(|((x, y), _)| *x = *y);
        c = apply_t(&x);
    }
    let mut x = apply(&c);
    x.iter_mut().zip(&y).zip(measured).filter(|(_, m)| **m).for_each(|((x, y), _)| *x = *y);
    x
}

#[test]
fn a_scheduled_solve_is_the_steps_it_names() {
    for seed in 1..4 {
        let dict = random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(seed + 30);
        let (truth, measured) = problem(seed);
        let mut ws = workspace(&truth, &measured);
        let out = solve_scheduled(&dict, &Sl0Config::DEFAULT, &schedule(), &mut ws).unwrap();
        assert_eq!((out.iterations, out.ended), (6, Ended::Scheduled));
        let r = reference(&dict, &schedule(), &truth, &measured);
        // f32 against f64 over six steps of a 144-value patch.
        assert!(rel_err(ws.patch(), &r) < 2e-5, "seed {seed}: {}", rel_err(ws.patch(), &r));
        // The warm path from the same start (the measurements, zeros elsewhere) is the same
        // solve.
        let mut warm = workspace(&truth, &measured);
        for (x, (&t, &m)) in warm.patch_mut().iter_mut().zip(truth.iter().zip(&measured)) {
            *x = if m { t } else { 0.0 };
        }
        solve_warm_scheduled(&dict, &Sl0Config::DEFAULT, &schedule(), &mut warm).unwrap();
        assert!(max_abs_diff(warm.patch(), ws.patch()) < 1e-6);
        // A schedule that starts from the band-gain fill is the warm solve from the fill.
        let filled = schedule().with_fill_start(true);
        let mut cold = workspace(&truth, &measured);
        solve_scheduled(&dict, &Sl0Config::DEFAULT, &filled, &mut cold).unwrap();
        let mut from_fill = workspace(&truth, &measured);
        let mut x = [0.0f32; N];
        slf_firmware::solver::fill::fill_bands::<PatchShape<3, 3, 2, 2, 4, N>>(from_fill.measurements(), &mut x);
        from_fill.patch_mut().copy_from_slice(&x);
        solve_warm_scheduled(&dict, &Sl0Config::DEFAULT, &filled, &mut from_fill).unwrap();
        assert!(max_abs_diff(cold.patch(), from_fill.patch()) < 1e-6);
        assert!(max_abs_diff(cold.patch(), ws.patch()) > 1e-4, "the fill start changed nothing");
    }
}

#[test]
fn a_scheduled_solve_stays_in_its_noise_ball_and_its_bound() {
    let dict = random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(41);
    let (truth, measured) = problem(5);
    let mut ws = workspace(&truth, &measured);
    let cfg = Sl0Config { noise: 0.02, ..Sl0Config::DEFAULT };
    solve_scheduled(&dict, &cfg, &schedule(), &mut ws).unwrap();
    let (mut r2, mut m) = (0.0f64, 0.0f64);
    for ((x, t), k) in ws.patch().iter().zip(&truth).zip(&measured) {
        if *k {
            r2 += f64::from(x - t).powi(2);
            m += 1.0;
        }
    }
    assert!(r2.sqrt() <= 0.02 * m.sqrt() * 1.001, "residual {} outside the ball {}", r2.sqrt(), 0.02 * m.sqrt());
    // The iteration bound holds on a schedule too.
    let mut ws = workspace(&truth, &measured);
    let out =
        solve_scheduled(&dict, &Sl0Config { max_iterations: 4, ..Sl0Config::DEFAULT }, &schedule(), &mut ws).unwrap();
    assert_eq!((out.iterations, out.ended), (4, Ended::IterationBound));
}

#[test]
fn a_scheduled_solve_of_half_pixel_views_meets_their_interpolating_measurements() {
    let dict = random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(43);
    let (truth, _) = problem(6);
    let shape = PatchShape::<3, 3, 2, 2, 4, N>::index;
    // View row 1 half: its entries measure the mean of lenslet rows s and s + 1.
    let half = HalfViews { rows: 0b10, cols: 0 };
    let mut ws = Box::new(Workspace::<PatchShape<3, 3, 2, 2, 4, N>>::new());
    ws.measurements_mut().set_half_views(half);
    let mut wanted = Vec::new();
    for s in 0..3 {
        for t in 0..3 {
            for u in 0..2 {
                for v in 0..2 {
                    let b = (s + t + u + v) % 4;
                    if u == 1 && s == 2 {
                        continue; // the last grid row of a half axis measures nothing
                    }
                    let y = if u == 1 {
                        0.5 * (truth[shape(s, t, u, v, b)] + truth[shape(s + 1, t, u, v, b)])
                    } else {
                        truth[shape(s, t, u, v, b)]
                    };
                    ws.measurements_mut().set(shape(s, t, u, v, b), y).unwrap();
                    wanted.push(((s, t, u, v, b), y));
                }
            }
        }
    }
    let out = solve_scheduled(&dict, &Sl0Config::DEFAULT, &schedule(), &mut ws).unwrap();
    assert_eq!(out.ended, Ended::Scheduled);
    let p = ws.patch();
    for ((s, t, u, v, b), y) in wanted {
        let got = if u == 1 {
            0.5 * (p[shape(s, t, u, v, b)] + p[shape(s + 1, t, u, v, b)])
        } else {
            p[shape(s, t, u, v, b)]
        };
        assert!((got - y).abs() < 1e-4, "({s}, {t}, {u}, {v}, {b}): {got} against {y}");
    }
}

fn scheduled_blob(
    members: &[Dictionary<PatchShape<3, 3, 2, 2, 4, 144>>],
    s: &Schedules<PatchShape<3, 3, 2, 2, 4, 144>>,
) -> &'static [u8] {
    let dims = [3, 3, 2, 2, 4];
    let mut out = vec![0u8; scheduled_blob_len(dims, members.len(), [s.cold.len(), s.warm.len(), s.alone.len()])];
    assert_eq!(write_blob_scheduled(members, Some(s), &mut out).unwrap(), out.len());
    Box::leak(out.into_boxed_slice())
}

/// Sets the CRC of a blob whose bytes were changed.
fn reseal(b: &mut [u8]) {
    let body = b.len() - 4;
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&b[..body]);
    b[body..].copy_from_slice(&crc.to_le_bytes());
}

#[test]
fn a_blob_carries_its_schedules_and_refuses_bad_ones() {
    let members = [random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(51), random_dictionary(52)];
    let warm = S::new(&[0.01, 0.001], &[2.0, 1.0], W::ONES).unwrap();
    let alone = S::new(&[0.5, 0.05, 0.005], &[1.0, 1.5, 2.0], weights()).unwrap().with_fill_start(true);
    let all = Schedules { cold: schedule(), warm, alone };
    let blob = scheduled_blob(&members, &all);
    let e = Ensemble::<PatchShape<3, 3, 2, 2, 4, 144>>::new(blob).unwrap();
    assert_eq!(e.schedules(), Some(all));
    assert!(e.schedules().unwrap().alone.fill_start() && !e.schedules().unwrap().cold.fill_start());
    assert_eq!(u16::from_le_bytes([blob[4], blob[5]]), 2);
    // Version 1 (no schedules) is still read, and has none.
    let mut v1 = vec![0u8; blob::blob_len([3, 3, 2, 2, 4], 2)];
    blob::write_blob(&members, &mut v1).unwrap();
    assert_eq!(u16::from_le_bytes([v1[4], v1[5]]), 1);
    assert_eq!(Ensemble::<PatchShape<3, 3, 2, 2, 4, 144>>::new(&v1).unwrap().schedules(), None);
    // The schedules start after the members: 2 x 4 * (9 + 9 + 4 + 4 + 16) bytes.
    let at = 24 + 2 * 4 * (9 + 9 + 4 + 4 + 16);
    let bad = |edit: &dyn Fn(&mut Vec<u8>)| {
        let mut b = blob.to_vec();
        edit(&mut b);
        reseal(&mut b);
        Ensemble::<PatchShape<3, 3, 2, 2, 4, 144>>::new(&b).err()
    };
    let part = |part| Some(DictionaryError::BadSchedule { part });
    assert_eq!(bad(&|b| b[at..at + 2].copy_from_slice(&0u16.to_le_bytes())), part("steps"));
    assert_eq!(bad(&|b| b[at..at + 2].copy_from_slice(&60u16.to_le_bytes())), part("steps"));
    assert_eq!(bad(&|b| b[at + 2] = 2), part("start"));
    assert_eq!(bad(&|b| b[at + 4..at + 8].copy_from_slice(&1.5f32.to_le_bytes())), part("sigma"));
    assert_eq!(bad(&|b| b[at + 4..at + 8].copy_from_slice(&f32::NAN.to_le_bytes())), part("sigma"));
    assert_eq!(bad(&|b| b[at + 28..at + 32].copy_from_slice(&2.5f32.to_le_bytes())), part("mu"));
    assert_eq!(bad(&|b| b[at + 52..at + 56].copy_from_slice(&0.0f32.to_le_bytes())), part("weights"));
    // A version 1 header over a version 2 body, and a truncated schedule section.
    assert!(matches!(bad(&|b| b[4] = 1), Some(DictionaryError::LengthMismatch { .. })));
    let mut short = blob[..blob.len() - 8].to_vec();
    let len = u32::from_le_bytes(short[20..24].try_into().unwrap()) - 8;
    short[20..24].copy_from_slice(&len.to_le_bytes());
    reseal(&mut short);
    assert_eq!(Ensemble::<PatchShape<3, 3, 2, 2, 4, 144>>::new(&short).err(), part("steps"));
}

/// A frame of a smooth scene on the small sensor, its decoder and the truth per patch.
struct Collect(Vec<(PatchOrigin, PatchReport, Vec<f32>)>);

impl PatchSink<PatchShape<3, 3, 2, 2, 4, N>> for Collect {
    type Error = ();
    fn accept(&mut self, o: PatchOrigin, p: &[f32; N], r: &PatchReport) -> Result<(), ()> {
        self.0.push((o, *r, p.to_vec()));
        Ok(())
    }
}

#[test]
fn an_ensemble_decodes_with_its_blobs_schedules_cold_sheared_and_seeded() {
    let members = [Dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>::dct(), random_dictionary(61)];
    let warm = S::new(&[0.02, 0.005, 0.001], &[1.5, 1.5, 1.0], W::ONES).unwrap();
    // A cold schedule like the hand-set one: sigma from 1 to 1e-4 of the start in 24 steps.
    let fall: Vec<f32> = (0..24).map(|t| 10f32.powf(-4.0 * t as f32 / 23.0)).collect();
    let cold = S::new(&fall, &[2.0; 24], W::ONES).unwrap();
    let model = EnsembleModel::new(
        Ensemble::new(scheduled_blob(&members, &Schedules { cold, warm, alone: cold })).unwrap(),
        MemberChoice::Screened(ChoiceRule::DEFAULT),
    );
    assert!(model.schedules().is_some());
    let unscheduled = model.clone().with_schedules(None);
    let mask = Mask::pixel(3, 2, 4, L3).unwrap();
    let (rows, cols) = SMALL.frame_size();
    // A plane at half a lenslet per view: the view `(u, v)` of lenslet `(lr, lc)` sees the
    // point `(lr + (u - 1) / 2, lc + (v - 1) / 2)` of a smooth texture.
    let value = |r: usize, c: usize| {
        let y = (r / 3) as f32 + 0.5 * ((r % 3) as f32 - 1.0);
        let x = (c / 3) as f32 + 0.5 * ((c % 3) as f32 - 1.0);
        10.5 + 0.3 * (y * 0.9).sin() * (x * 0.7).cos()
    };
    let frames: Vec<Vec<f32>> = (0..2).map(|_| (0..rows * cols).map(|i| value(i / cols, i % cols)).collect()).collect();
    let frames: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, rows, cols).unwrap()).collect();
    let decode = |m: &EnsembleModel<PatchShape<3, 3, 2, 2, 4, 144>>, halves: bool| {
        let dec = small_decoder(mask).with_disparities(DisparityRange::new(-1, 1).unwrap().with_halves(halves));
        let mut sink = Collect(Vec::new());
        let mut ws = Box::new(Workspace::<PatchShape<3, 3, 2, 2, 4, N>>::new());
        let report = dec.decode_frame(m, (2, 2), &mut FrameSource::new(&frames), &mut sink, &mut ws);
        (report, sink.0)
    };
    for halves in [false, true] {
        let (report, patches) = decode(&model, halves);
        assert_eq!(report.failed_tiles, 0);
        assert!(!patches.is_empty());
        // Every solved patch ended its schedule: cold (DCT), then warm (the member).
        for (_, r, p) in &patches {
            assert!(matches!(r.outcome.ended, Ended::Scheduled | Ended::Flat), "{:?}", r.outcome);
            assert!(p.iter().all(|x| x.is_finite()));
        }
        assert!(patches.iter().any(|(o, _, _)| o.disparity != Disparity::ZERO) || !halves);
        // The hand-set schedule decodes the same frame to nearly the same scene (a smooth
        // one): mean difference per value, in units of the sensor's range.
        let (_, hand) = decode(&unscheduled, halves);
        let (mut diff, mut values) = (0.0f64, 0usize);
        for ((o, _, p), (q, r, h)) in patches.iter().zip(&hand) {
            assert_eq!(o, q);
            assert!(matches!(r.outcome.ended, Ended::SigmaMin | Ended::Flat));
            diff += p.iter().zip(h).map(|(a, b)| f64::from((a - b).abs())).sum::<f64>();
            values += p.len();
        }
        assert!(diff / (values as f64) < 0.01, "mean difference {}", diff / values as f64);
    }
    // Seeded: one warm scheduled solve from the estimate (the warm schedule's 3 steps).
    let (truth, measured) = problem(7);
    let mut ws = workspace(&truth, &measured);
    let mut r = rng(8);
    for (x, t) in ws.patch_mut().iter_mut().zip(&truth) {
        *x = t + r.random_range(-0.02..0.02);
    }
    let done = model.decode_seeded(&Sl0Config::DEFAULT, &mut ws).unwrap();
    assert_eq!((done.solves, done.outcome.iterations, done.outcome.ended), (1, 3, Ended::Scheduled));
    assert!(rel_err32(ws.patch(), &truth) < 0.05);
}

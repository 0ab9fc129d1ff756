//! Half-pixel shears (issue 19): the read of a half-pixel sheared patch against the sensor
//! pixels found from the definition (each pixel's fractional grid position), the
//! interpolating operator and its projection against a dense f64 reference
//! (`S - A^T (A A^T)^-1 (A S - y)` with `A = M K`, `M` written from the definition), the
//! full-size blocks (every entry measured on a 5 x 5 grid) against the same reference, the
//! noise ball's move as a fraction of the exact one, a solve that meets its measurements,
//! and the chosen disparity of a plane at a half-pixel disparity.

mod common;

use common::*;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use slf_firmware::ball::Ball;
use slf_firmware::disparity::{Disparity, HalfViews};
use slf_firmware::fractional::{project_fractional, to_sensor};
use slf_firmware::shape::ValueCount;
use slf_firmware::*;

/// One measurement of a patch, from the definition: the grid entries it averages.
struct Row {
    /// Patch entry where the read stores it (its first grid position).
    slot: usize,
    /// `(entry, weight)` pairs.
    taps: Vec<(usize, f64)>,
}

/// Where sensor lenslet `l` of view `w` (of 3) falls on the grid of a patch at lenslet
/// `o` sheared to `h / 2` pixels, from the definition: view `w` is shifted by `-d (w - 1)`,
/// so the pixel sits at `l - o + d (w - 1)`. `None` off the grid `[0, 2]`.
fn grid_position(l: usize, o: usize, w: usize, h: i8) -> Option<f64> {
    let p = l as f64 - o as f64 + f64::from(h) / 2.0 * (w as f64 - 1.0);
    (-1e-9..=2.0 + 1e-9).contains(&p).then_some(p)
}

/// The taps of a pixel at grid position `p` along one axis: one at a whole position, two
/// halves between positions.
fn taps_1d(p: f64) -> Vec<(usize, f64)> {
    let lo = p.floor();
    if (p - lo).abs() < 1e-9 { vec![(lo as usize, 1.0)] } else { vec![(lo as usize, 0.5), (lo as usize + 1, 0.5)] }
}

/// Every measurement of the patch at `origin` (window `window`) sheared to `h / 2`, with its
/// sensor pixel `(row, col)` and snapshot, from the definition.
fn rows_of(mask: &Mask, origin: (usize, usize), window: (usize, usize), h: i8) -> Vec<(Row, usize, usize, usize)> {
    let mut out = Vec::new();
    for lr in 0..10 {
        for lc in 0..11 {
            for u in 0..2 {
                for v in 0..2 {
                    let (w, x) = (window.0 + u, window.1 + v);
                    let (Some(ps), Some(pt)) = (grid_position(lr, origin.0, w, h), grid_position(lc, origin.1, x, h))
                    else {
                        continue;
                    };
                    let (row, col) = (lr * 3 + w, lc * 3 + x);
                    for j in 0..mask.snapshots() {
                        let b = mask.band(j, row, col).unwrap() as usize;
                        let mut taps = Vec::new();
                        for &(s, ws) in &taps_1d(ps) {
                            for &(t, wt) in &taps_1d(pt) {
                                taps.push((SmallShape::index(s, t, u, v, b), ws * wt));
                            }
                        }
                        let slot = SmallShape::index(ps.floor() as usize, pt.floor() as usize, u, v, b);
                        out.push((Row { slot, taps }, j, row, col));
                    }
                }
            }
        }
    }
    out
}

/// `A = M K` densely: one row per measurement, `K` the dictionary's synthesis.
fn dense_a(rows: &[&Row], kd: &[f64], n: usize) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), n, |r, j| rows[r].taps.iter().map(|&(i, w)| w * kd[i * n + j]).sum())
}

#[test]
fn half_pixel_read_and_projection_match_the_dense_definition() {
    let (rows, cols) = SMALL.frame_size();
    for (seed, k, h, origin, window) in [
        (1u64, 1u8, 1i8, (3usize, 4usize), (0usize, 0usize)),
        (2, 2, -1, (4, 3), (1, 1)),
        (3, 3, 3, (3, 4), (1, 0)),
        (4, 1, -3, (4, 4), (0, 1)),
        // Every band at every pixel: a whole view's 9 positions are one block (the large factor).
        (5, 4, 1, (3, 4), (1, 1)),
    ] {
        let mask = Mask::pixel(seed, k, 4, L3).unwrap();
        let dec = small_decoder(mask);
        let dict = random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(seed + 20);
        let (kd, n) = dense_kronecker(dict.synthesis());
        let mut r = rng(seed);
        let c: Vec<f32> = (0..n).map(|_| r.random_range(-1.0f32..1.0)).collect();
        let x = dense_apply(&kd, n, &c);
        // Frames: noise everywhere, the interpolated grid values at the patch's pixels.
        let mut frames: Vec<Vec<f32>> =
            (0..k).map(|_| (0..rows * cols).map(|_| 10.0 + r.random_range(-1.0f32..1.0)).collect()).collect();
        let defined = rows_of(&mask, origin, window, h);
        for (row, j, pr, pc) in &defined {
            let value: f64 = row.taps.iter().map(|&(i, w)| w * x[i]).sum();
            frames[*j][pr * cols + pc] = 10.0 + value as f32;
        }
        let raw: Vec<RawFrame<f32>> = frames.iter().map(|f| RawFrame::new(f, rows, cols).unwrap()).collect();
        let mut ws = Box::new(Workspace::<PatchShape<3, 3, 2, 2, 4, 144>>::new());
        let o = PatchOrigin {
            lenslet_row: origin.0 as u16,
            lenslet_col: origin.1 as u16,
            view_row: window.0 as u8,
            view_col: window.1 as u8,
            disparity: Disparity::halves(h),
        };
        let (flags, excluded) = dec.read_patch(o, &mut FrameSource::new(&raw), &mut ws).unwrap();
        assert!(flags.is_empty() && excluded == 0);
        let m = ws.measurements();
        // Half views: the window's views an odd number of steps from the centre.
        let odd = |w: usize| (w as i64 - 1).rem_euclid(2) == 1;
        let half = m.half_views();
        for i in 0..2 {
            assert_eq!(half.row(i), odd(window.0 + i), "case {seed}: view row {i}");
            assert_eq!(half.col(i), odd(window.1 + i), "case {seed}: view col {i}");
        }
        assert_eq!(m.count(), defined.len(), "case {seed}: measurements");
        let mut truth = Vec::new();
        for (row, ..) in &defined {
            let want: f64 = row.taps.iter().map(|&(i, w)| w * x[i]).sum();
            let got = m.get(row.slot).unwrap_or_else(|| panic!("case {seed}: slot {} not measured", row.slot));
            assert!((f64::from(got) - want).abs() < 2e-6, "case {seed}: read {got} vs {want}");
            truth.push(f64::from(got));
        }
        // The projection of random coefficients onto these measurements, against the dense
        // f64 `S - A^T (A A^T)^-1 (A S - y)`.
        let rows_ref: Vec<&Row> = defined.iter().map(|(row, ..)| row).collect();
        let a = dense_a(&rows_ref, &kd, n);
        let s0: Vec<f32> = (0..n).map(|_| r.random_range(-1.0f32..1.0)).collect();
        let s = DVector::from_iterator(n, s0.iter().map(|&v| f64::from(v)));
        let y = DVector::from_vec(truth);
        let chol = (&a * a.transpose()).cholesky().expect("A A^T positive definite");
        let want = &s - a.transpose() * chol.solve(&(&a * &s - &y));
        let mut coeffs: [f32; 144] = s0.clone().try_into().unwrap();
        let mut scratch = [0.0f32; 144];
        let exact = Ball::new(0.0, 0.0, m.count() as u32, 0);
        let before = project_fractional(&dict, &mut coeffs, &mut scratch, m, &exact, None);
        let err = coeffs.iter().zip(want.iter()).map(|(&g, w)| (f64::from(g) - w).abs()).fold(0.0, f64::max);
        assert!(err < 2e-5, "case {seed}: projection differs from the dense one by {err}");
        let residual = (&a * &s - &y).norm();
        assert!((f64::from(before) - residual).abs() < 1e-4 * residual.max(1.0), "case {seed}: residual norm");
        // Adjointness of the operator the projection uses: <A s, z> = <s, A^T z> holds for
        // the dense A by construction; the fast projection is exact only if its `M^T` is
        // `M`'s adjoint, which the match above shows. After it, A S = y.
        let after = DVector::from_iterator(n, coeffs.iter().map(|&v| f64::from(v)));
        assert!((&a * after - &y).norm() < 1e-4, "case {seed}: projected patch misses its measurements");
    }
}

/// Every entry of every view measured on a 5 x 5 grid, one view of each kind (whole,
/// half row, half column, both): blocks of 25 diagonal, of 20 in chains, and of 16 coupled
/// in two dimensions, the sizes past the small factor, with some entries left out so
/// blocks of every size between occur. Against the dense f64 projection, from the
/// definition (a half axis averages grid positions `s` and `s + 1`).
#[test]
fn full_blocks_project_like_the_dense_definition() {
    type Grid = PatchShape<5, 5, 2, 2, 2, 200>;
    let dict = random_dictionary::<PatchShape<5, 5, 2, 2, 2, 200>>(41);
    let (kd, n) = dense_kronecker(dict.synthesis());
    let half = HalfViews { rows: 0b10, cols: 0b10 };
    for (case, keep) in [(0, 1.0f32), (1, 0.6), (2, 0.3)] {
        let mut r = rng(50 + case);
        let mut m = Measurements::<ValueCount<200>>::new();
        let mut rows: Vec<Vec<(usize, f64)>> = Vec::new();
        let mut y = Vec::new();
        for u in 0..2 {
            for v in 0..2 {
                let (hs, ht) = (usize::from(half.row(u)), usize::from(half.col(v)));
                for s in 0..5 - hs {
                    for t in 0..5 - ht {
                        for b in 0..2 {
                            if r.random_range(0.0f32..1.0) >= keep {
                                continue;
                            }
                            let w = 1.0 / ((1 + hs) * (1 + ht)) as f64;
                            let taps = (0..=hs)
                                .flat_map(|a| (0..=ht).map(move |c| (Grid::index(s + a, t + c, u, v, b), w)))
                                .collect();
                            let value = r.random_range(-1.0f32..1.0);
                            m.set(Grid::index(s, t, u, v, b), value).unwrap();
                            rows.push(taps);
                            y.push(f64::from(value));
                        }
                    }
                }
            }
        }
        m.set_half_views(half);
        let a = DMatrix::<f64>::from_fn(rows.len(), n, |i, j| rows[i].iter().map(|&(e, w)| w * kd[e * n + j]).sum());
        let s0: [f32; 200] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
        let s = DVector::from_iterator(n, s0.iter().map(|&v| f64::from(v)));
        let y = DVector::from_vec(y);
        let chol = (&a * a.transpose()).cholesky().expect("A A^T positive definite");
        let want = &s - a.transpose() * chol.solve(&(&a * &s - &y));
        let mut coeffs = s0;
        let mut scratch = [0.0f32; 200];
        project_fractional(&dict, &mut coeffs, &mut scratch, &m, &Ball::new(0.0, 0.0, m.count() as u32, 0), None);
        let err = coeffs.iter().zip(want.iter()).map(|(&g, w)| (f64::from(g) - w).abs()).fold(0.0, f64::max);
        assert!(err < 2e-5, "case {case}: projection differs from the dense one by {err}");
    }
}

#[test]
fn the_noise_ball_moves_a_fraction_of_the_exact_projection() {
    let mask = Mask::pixel(7, 2, 4, L3).unwrap();
    let defined = rows_of(&mask, (3, 3), (0, 0), 1);
    let dict = random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(31);
    let mut m = Measurements::<ValueCount<144>>::new();
    let mut r = rng(7);
    for (row, ..) in &defined {
        m.set(row.slot, r.random_range(0.0f32..1.0)).unwrap();
    }
    m.set_half_views(HalfViews { rows: 0b01, cols: 0b01 });
    let s0: [f32; 144] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
    let mut scratch = [0.0f32; 144];
    let mut exact = s0;
    project_fractional(&dict, &mut exact, &mut scratch, &m, &Ball::new(0.0, 0.0, m.count() as u32, 0), None);
    let mut ball = s0;
    project_fractional(&dict, &mut ball, &mut scratch, &m, &Ball::new(0.05, 0.0, m.count() as u32, 4), None);
    // ball - s0 = scale (exact - s0), one scale in (0, 1) for every coefficient.
    let (num, den) = ball.iter().zip(&exact).zip(&s0).fold((0.0f64, 0.0f64), |(n, d), ((&b, &e), &s)| {
        (n + f64::from(b - s) * f64::from(e - s), d + f64::from(e - s).powi(2))
    });
    let scale = num / den;
    assert!(scale > 0.0 && scale < 1.0, "scale {scale}");
    for ((&b, &e), &s) in ball.iter().zip(&exact).zip(&s0) {
        let want = f64::from(s) + scale * f64::from(e - s);
        assert!((f64::from(b) - want).abs() < 1e-5, "{b} vs {want}");
    }
}

/// A ball weighted by each measurement's variance (shot noise, unequal gains): the half-pixel
/// step reading the solve's table of weights (`projection::weigh`, what a descent passes)
/// moves the patch to the same bits as the step computing each weight. Fails if the table
/// were read at another entry than the measurement's.
#[test]
fn a_weighted_ball_reads_its_weights_from_the_table_to_the_same_bits() {
    let mask = Mask::pixel(7, 2, 4, L3).unwrap();
    let defined = rows_of(&mask, (3, 3), (0, 0), 1);
    let dict = random_dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>(32);
    let mut m = Measurements::<ValueCount<144>>::new();
    let mut r = rng(8);
    for (row, ..) in &defined {
        m.set(row.slot, r.random_range(0.1f32..1.0)).unwrap();
    }
    m.set_gains(&[0.6, 1.3, 2.1, 0.9]).unwrap();
    m.set_half_views(HalfViews { rows: 0b01, cols: 0b01 });
    let ball = Ball::new(0.01, 0.02, m.count() as u32, 4);
    assert!(ball.is_weighted());
    let mut table = [0.0f32; 144];
    slf_firmware::projection::weigh::<PatchShape<3, 3, 2, 2, 4, 144>>(&m, &ball, &mut table);
    let s0: [f32; 144] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
    let mut scratch = [0.0f32; 144];
    let (mut computed, mut read) = (s0, s0);
    let n0 = project_fractional(&dict, &mut computed, &mut scratch, &m, &ball, None);
    let n1 = project_fractional(&dict, &mut read, &mut scratch, &m, &ball, Some(&table));
    assert_eq!(n0.to_bits(), n1.to_bits(), "residual norms");
    assert!(computed.iter().zip(&read).all(|(a, b)| a.to_bits() == b.to_bits()), "the moves differ");
    assert!(read.iter().zip(&s0).any(|(a, b)| a != b), "the ball did not move the patch");
}

#[test]
fn a_half_pixel_solve_meets_its_measurements_and_to_sensor_gives_the_pixels() {
    let mask = Mask::pixel(11, 3, 4, L3).unwrap();
    let dict = Dictionary::<PatchShape<3, 3, 2, 2, 4, 144>>::dct();
    let defined = rows_of(&mask, (3, 3), (0, 1), -1);
    let truth = smooth_patch::<PatchShape<3, 3, 2, 2, 4, 144>>(5);
    let mut ws = Box::new(Workspace::<PatchShape<3, 3, 2, 2, 4, 144>>::new());
    for (row, ..) in &defined {
        let y: f64 = row.taps.iter().map(|&(i, w)| w * f64::from(truth[i])).sum();
        ws.measurements_mut().set(row.slot, y as f32).unwrap();
    }
    // Window (0, 1) at d = -1/2: view rows 0 (w = 0) half, 1 not; columns 1 not, 2 half.
    ws.measurements_mut().set_half_views(HalfViews { rows: 0b01, cols: 0b10 });
    let outcome = solve(&dict, &Sl0Config::DEFAULT, &mut ws).unwrap();
    assert!(!outcome.hit_bound());
    let patch = *ws.patch();
    for (row, ..) in &defined {
        let want = ws.measurements().get(row.slot).unwrap();
        let got: f64 = row.taps.iter().map(|&(i, w)| w * f64::from(patch[i])).sum();
        assert!((got - f64::from(want)).abs() < 1e-4, "measurement {want} vs the decode's {got}");
    }
    // to_sensor: each slot becomes the value its pixel measured, from the taps.
    let mut sensor = patch;
    to_sensor::<PatchShape<3, 3, 2, 2, 4, 144>>(ws.measurements().half_views(), &mut sensor);
    for (row, ..) in &defined {
        let want: f64 = row.taps.iter().map(|&(i, w)| w * f64::from(patch[i])).sum();
        assert!((f64::from(sensor[row.slot]) - want).abs() < 1e-6, "to_sensor at {}", row.slot);
    }
}

#[test]
fn a_plane_at_a_half_pixel_disparity_is_chosen_off_the_edges() {
    // Lenslets of 5 x 5 views (centre 2): at d = 1/2 the views two steps out shift by a
    // whole lenslet, the others by a half. A smooth random texture at disparity 0.5: view
    // (w, x) of lenslet (l, c) sees the texture at (l + 0.5 (w - 2), c + 0.5 (x - 2)),
    // bilinear between its samples (the HCI convention of `disparity`).
    const L5: LensletSize = LensletSize { rows: 5, cols: 5 };
    let geometry = SensorGeometry { lenslets: (12, 12), lenslet: L5 };
    let (rows, cols) = geometry.frame_size();
    let mut r = rng(41);
    let tex: Vec<f64> = (0..24 * 24).map(|_| r.random_range(0.1f64..0.9)).collect();
    let texture = |y: f64, x: f64| {
        let (y0, x0) = (y.floor(), x.floor());
        let (fy, fx) = (y - y0, x - x0);
        let at = |a: f64, b: f64| tex[((a + 6.0) as usize) * 24 + (b + 6.0) as usize];
        (1.0 - fy) * ((1.0 - fx) * at(y0, x0) + fx * at(y0, x0 + 1.0))
            + fy * ((1.0 - fx) * at(y0 + 1.0, x0) + fx * at(y0 + 1.0, x0 + 1.0))
    };
    let mask = Mask::pixel(5, 1, 4, L5).unwrap();
    let frame: Vec<f32> = (0..rows * cols)
        .map(|i| {
            let (row, col) = (i / cols, i % cols);
            let (l, w, c, x) = (row / 5, row % 5, col / 5, col % 5);
            let b = f64::from(mask.band(0, row, col).unwrap());
            let v = texture(l as f64 + 0.5 * (w as f64 - 2.0), c as f64 + 0.5 * (x as f64 - 2.0));
            10.0 + (v * (0.6 + 0.1 * b)) as f32
        })
        .collect();
    let raw = [RawFrame::new(&frame, rows, cols).unwrap()];
    let decoder = |range: DisparityRange| {
        Small::new(DecoderConfig {
            sensor: geometry,
            mask,
            raw: OFFSET,
            defects: DefectList::EMPTY,
            sl0: Sl0Config::DEFAULT,
        })
        .unwrap()
        .with_disparities(range)
    };
    let halves = decoder(DisparityRange::new(-1, 1).unwrap().with_halves(true));
    assert!(halves.disparities().has_halves());
    // Blocks whose shear stays on the sensor (1 lenslet either side).
    let mut chosen = Vec::new();
    for row in 1..=8 {
        for col in 1..=8 {
            chosen.push(halves.choose_disparity(row, col, &mut FrameSource::new(&raw)).unwrap());
        }
    }
    assert!(chosen.iter().all(|&d| d == Disparity::halves(1)), "{chosen:?}");
    // Without halves the same blocks pick a whole disparity.
    let whole = decoder(DisparityRange::new(-1, 1).unwrap());
    assert!(whole.choose_disparity(3, 3, &mut FrameSource::new(&raw)).unwrap().is_whole());
}

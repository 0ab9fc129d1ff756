//! Pixels that share view cells behind a turned lenslet grid (issue 52): the projection's
//! step against a dense f64 reference (`S + A^T W^-1 (y - A S)`, `A = M K`, `W` the rows of
//! `M M^T` summed, `M` written here from the definition: a pixel `width` cells wide whose centre sits at its place in
//! its cell records each cell's value weighted by the share of its square the cell covers,
//! cells found on the sensor through the shear's whole-lenslet shifts, a share outside the
//! patch given to the pixel's own cell), on grids of pixels narrower and wider than a cell,
//! unsheared and sheared; where no measurement shares a cell, the exact projection; the
//! prediction `to_sensor` against `M x`; on a band measured everywhere, half a cell off,
//! the residual shrinks where a step by the diagonal alone would grow it; a second step
//! with the row sums the first one found and kept ([`RowSums`]) against the reference too;
//! the share of a pixel's square outside the patch ([`Reach`]) against the definition's.

mod common;

use common::*;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use slf_firmware::Shape as _;
use slf_firmware::ball::Ball;
use slf_firmware::disparity::HalfViews;
use slf_firmware::projection::weigh;
use slf_firmware::shape::ValueCount;
use slf_firmware::shares::{Reach, RowSums, project_shares, to_sensor};
use slf_firmware::workspace::{CellShares, MAX_SHARE_VIEWS, Measurements, PLACE_UNIT};
use slf_firmware::*;

const PS: usize = 2;
const PT: usize = 3;
const PU: usize = 3;
const PV: usize = 3;
const B: usize = 2;
const N: usize = PS * PT * PU * PV * B;
type Shape = PatchShape<PS, PT, PU, PV, B, N>;

/// The grid position and view of sensor cell `p` along an axis, by search over the patch.
fn find(p: i64, views: usize, len: usize, shift: &[i8]) -> Option<(usize, usize)> {
    (0..len)
        .flat_map(|s| (0..views).map(move |u| (s, u)))
        .find(|&(s, u)| (s as i64 + i64::from(shift[u])) * views as i64 + u as i64 == p)
}

/// The shares of a box `[c - w/2, c + w/2]` in the unit cells `k - 1, k, k + 1` around
/// its own cell `k` (the box's centre `c` in `[k, k + 1)`), as fractions of `w`.
fn box_1d(c: f64, k: i64, w: f64) -> [f64; 3] {
    let (a, b) = (c - w / 2.0, c + w / 2.0);
    core::array::from_fn(|i| {
        let lo = (k + i as i64 - 1) as f64;
        ((b.min(lo + 1.0) - a.max(lo)).max(0.0)) / w
    })
}

/// The grid positions (with their weights) that sensor cell `p`'s value is along an axis:
/// its own, or for a half view the mean of its own and the next; `None` outside the patch
/// (not found, or a half view's next position past it).
fn cell(p: i64, views: usize, len: usize, shift: &[i8], half: u32) -> Option<Vec<(usize, usize, f64)>> {
    let (s, u) = find(p, views, len, shift)?;
    if half >> u & 1 == 0 {
        return Some(vec![(s, u, 1.0)]);
    }
    (s + 1 < len).then(|| vec![(s, u, 0.5), (s + 1, u, 0.5)])
}

/// Measurement rows of pixel `(s, t, u, v)` from the definition: `(entry of band 0,
/// weight)`; a view of `half` (rows, columns) is half a lenslet off the grid, its cell the
/// mean of two grid positions.
fn taps(
    (s, t, u, v): (usize, usize, usize, usize),
    place: (f64, f64),
    shares: &CellShares,
    half: HalfViews,
) -> Vec<(usize, f64)> {
    // A share outside the patch: taken out of the measurement (known outside), or given to
    // the pixel's own cell.
    let own = if shares.known_outside { 0.0 } else { 1.0 };
    let p = (s as i64 + i64::from(shares.shift.0[u])) * PU as i64 + u as i64;
    let q = (t as i64 + i64::from(shares.shift.1[v])) * PV as i64 + v as i64;
    let mut rows = box_1d(p as f64 + 0.5 + place.0, p, f64::from(shares.width.0));
    let mut cols = box_1d(q as f64 + 0.5 + place.1, q, f64::from(shares.width.1));
    for (k, d) in [(0usize, -1i64), (2, 1)] {
        if cell(p + d, PU, PS, &shares.shift.0, half.rows).is_none() {
            rows[1] += own * rows[k];
            rows[k] = 0.0;
        }
        if cell(q + d, PV, PT, &shares.shift.1, half.cols).is_none() {
            cols[1] += own * cols[k];
            cols[k] = 0.0;
        }
    }
    let mut out = Vec::new();
    for (i, wr) in rows.iter().enumerate() {
        for (j, wc) in cols.iter().enumerate() {
            if wr * wc > 0.0 {
                for (s2, u2, a) in cell(p + i as i64 - 1, PU, PS, &shares.shift.0, half.rows).unwrap() {
                    for (t2, v2, b) in cell(q + j as i64 - 1, PV, PT, &shares.shift.1, half.cols).unwrap() {
                        out.push((Shape::index(s2, t2, u2, v2, 0), wr * wc * a * b));
                    }
                }
            }
        }
    }
    out
}

/// A patch's measurements: `per_band` random pixels of each band, random places (whole
/// place units, so the stored places are exact) and values. Returns the rows of `M`
/// (entries, weights) and the values.
type Rows = Vec<(usize, Vec<(usize, f64)>)>;

/// (each row: the entry it was set at, and its taps)
fn measure(
    shares: &CellShares,
    per_band: usize,
    seed: u64,
    place: Option<f64>,
) -> (Measurements<ValueCount<N>>, Rows, Vec<f64>) {
    measure_half(shares, HalfViews::NONE, per_band, seed, place)
}

/// [`measure`] with the views of `half` half a lenslet off the grid: only pixels whose own
/// cell lies in the patch are measured.
fn measure_half(
    shares: &CellShares,
    half: HalfViews,
    per_band: usize,
    seed: u64,
    place: Option<f64>,
) -> (Measurements<ValueCount<N>>, Rows, Vec<f64>) {
    let mut r = rng(seed);
    let mut m = Measurements::<ValueCount<N>>::new();
    m.set_shares(Some(*shares)).unwrap();
    m.set_half_views(half);
    let own = |s: usize, t: usize, u: usize, v: usize| {
        (half.rows >> u & 1 == 0 || s + 1 < PS) && (half.cols >> v & 1 == 0 || t + 1 < PT)
    };
    let pixels: Vec<(usize, usize, usize, usize)> = (0..PS)
        .flat_map(|s| (0..PT).flat_map(move |t| (0..PU).flat_map(move |u| (0..PV).map(move |v| (s, t, u, v)))))
        .filter(|&(s, t, u, v)| own(s, t, u, v))
        .collect();
    let mut places = Vec::new();
    for &(s, t, u, v) in &pixels {
        let unit = |r: &mut rand_chacha::ChaCha8Rng| f64::from(r.random_range(-126i32..=126)) / f64::from(PLACE_UNIT);
        let place = place.map_or_else(|| (unit(&mut r), unit(&mut r)), |p| (p, p));
        m.set_place(Shape::pixel_index(s, t, u, v) / B, (place.0 as f32, place.1 as f32)).unwrap();
        places.push(place);
    }
    let (mut rows, mut y) = (Vec::new(), Vec::new());
    for b in 0..B {
        let mut order: Vec<usize> = (0..pixels.len()).collect();
        for i in (1..order.len()).rev() {
            order.swap(i, r.random_range(0..=i));
        }
        for &i in order.iter().take(per_band) {
            let value = r.random_range(-1.0f32..1.0);
            let entry = Shape::pixel_index(pixels[i].0, pixels[i].1, pixels[i].2, pixels[i].3) + b;
            m.set(entry, value).unwrap();
            rows.push((entry, taps(pixels[i], places[i], shares, half).into_iter().map(|(e, w)| (e + b, w)).collect()));
            y.push(f64::from(value));
        }
    }
    (m, rows, y)
}

fn shares_of(width: (f32, f32), rows: [i8; 3], cols: [i8; 3]) -> CellShares {
    let mut c = CellShares::unsheared(width);
    c.shift.0[..3].copy_from_slice(&rows);
    c.shift.1[..3].copy_from_slice(&cols);
    const { assert!(PU <= MAX_SHARE_VIEWS) };
    c
}

/// `A = M K` and `W` (the rows of `M M^T` summed) of measurement rows.
fn dense(rows: &Rows, kd: &[f64], n: usize) -> (DMatrix<f64>, DVector<f64>) {
    let mut mm = DMatrix::<f64>::zeros(rows.len(), n);
    for (i, (_, taps)) in rows.iter().enumerate() {
        for &(e, w) in taps {
            mm[(i, e)] += w;
        }
    }
    let a = DMatrix::<f64>::from_fn(rows.len(), n, |i, j| rows[i].1.iter().map(|&(e, w)| w * kd[e * n + j]).sum());
    let g = &mm * mm.transpose();
    let w = DVector::from_iterator(rows.len(), g.row_iter().map(|r| r.sum()));
    (a, w)
}

#[test]
fn the_projection_matches_the_dense_definition() {
    let dict = random_dictionary::<PatchShape<PS, PT, PU, PV, B, N>>(5);
    let (kd, n) = dense_kronecker(dict.synthesis());
    for (case, shares, per_band) in [
        // Pixels narrower than a cell (pitch 3.06 px for 3 views), unsheared.
        (0u64, shares_of((3.0 / 3.06, 3.0 / 3.06), [0; 3], [0; 3]), 12),
        // Wider than a cell (pitch 2.9 px): a pixel reaches three cells along an axis.
        (1, shares_of((3.0 / 2.9, 3.0 / 2.95), [0; 3], [0; 3]), 20),
        // Sheared by whole lenslets: a cell's neighbour on the sensor is elsewhere in the patch.
        (2, shares_of((3.0 / 3.1, 3.0 / 3.02), [1, 0, -1], [-1, 0, 1]), 20),
        // Every pixel measures both bands.
        (3, shares_of((3.0 / 3.04, 3.0 / 3.04), [0; 3], [0; 3]), PS * PT * PU * PV),
        // One measurement a band: none shares a cell with another, the step is the exact
        // projection.
        (4, shares_of((3.0 / 3.04, 3.0 / 3.04), [0; 3], [0; 3]), 1),
        // Sheared, the shares outside the patch taken out of the measurements (known
        // outside): no part of the model.
        (5, CellShares { known_outside: true, ..shares_of((3.0 / 2.9, 3.0 / 3.1), [1, 0, -1], [-1, 0, 1]) }, 20),
    ] {
        let (m, rows, y) = measure(&shares, per_band, 10 + case, None);
        assert_eq!(m.count(), rows.len());
        let (a, w) = dense(&rows, &kd, n);
        let mut r = rng(case);
        let s0: [f32; N] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
        let s = DVector::from_iterator(n, s0.iter().map(|&v| f64::from(v)));
        let y = DVector::from_vec(y);
        let want = &s + a.transpose() * (&y - &a * &s).component_div(&w);
        let mut coeffs = s0;
        let mut scratch = [0.0f32; N];
        let mut sums = RowSums::new();
        let exact = Ball::new(0.0, 0.0, m.count() as u32, 0);
        let before = project_shares(&dict, &mut coeffs, &mut scratch, &m, &exact, &mut sums, None);
        let residual = (&a * &s - &y).norm();
        assert!((f64::from(before) - residual).abs() < 1e-4 * residual.max(1.0), "case {case}: residual norm");
        let err = coeffs.iter().zip(want.iter()).map(|(&g, w)| (f64::from(g) - w).abs()).fold(0.0, f64::max);
        assert!(err < 5e-5, "case {case}: step differs from the dense one by {err}");
        // A second step with the row sums the first one found (a descent's later steps),
        // from another start.
        let s1: [f32; N] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
        let t = DVector::from_iterator(n, s1.iter().map(|&v| f64::from(v)));
        let want = &t + a.transpose() * (&y - &a * &t).component_div(&w);
        let mut again = s1;
        project_shares(&dict, &mut again, &mut scratch, &m, &exact, &mut sums, None);
        let err = again.iter().zip(want.iter()).map(|(&g, w)| (f64::from(g) - w).abs()).fold(0.0, f64::max);
        assert!(err < 5e-5, "case {case}: a step with kept row sums differs from the dense one by {err}");
        if case == 4 {
            let g = &a * a.transpose();
            let exact = &s - a.transpose() * g.cholesky().unwrap().solve(&(&a * &s - &y));
            let err = coeffs.iter().zip(exact.iter()).map(|(&g, w)| (f64::from(g) - w).abs()).fold(0.0, f64::max);
            assert!(err < 5e-5, "isolated measurements: the exact projection, off by {err}");
        }

        // The prediction of every measurement from a patch: M x.
        let x: [f32; N] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
        let mut predicted = x;
        to_sensor::<PatchShape<PS, PT, PU, PV, B, N>>(&m, &mut predicted, &mut scratch);
        for (entry, row) in &rows {
            let want: f64 = row.iter().map(|&(e, w)| w * f64::from(x[e])).sum();
            assert!((f64::from(predicted[*entry]) - want).abs() < 1e-5, "case {case}: prediction at {entry}");
        }
    }
}

/// A patch sheared to a half disparity behind the grid: every other view is half a lenslet
/// off its grid, its cell the mean of two grid positions (`fractional.rs`'s model), and a
/// pixel's measurement the shares of its cells so read (a cell whose next position lies past
/// the patch outside it). The step against the dense definition, a second step with the
/// kept row sums, the prediction `to_sensor`; a value set at the last grid position of a
/// half view (no cell in the patch) is no measurement: ignored, as `set_half_views` says.
#[test]
fn half_views_match_the_dense_definition() {
    let dict = random_dictionary::<PatchShape<PS, PT, PU, PV, B, N>>(8);
    let (kd, n) = dense_kronecker(dict.synthesis());
    for (case, shares, half, per_band) in [
        // d = +1/2 on 3 x 3 views: views 0 and 2 half, view 0 one lenslet on.
        (0u64, shares_of((3.0 / 3.06, 3.0 / 3.02), [1, 0, 0], [1, 0, 0]), HalfViews { rows: 0b101, cols: 0b101 }, 14),
        // d = -1/2: views 0 and 2 half, view 2 one lenslet on; pixels wider than a cell.
        (1, shares_of((3.0 / 2.9, 3.0 / 2.95), [0, 0, 1], [0, 0, 1]), HalfViews { rows: 0b101, cols: 0b101 }, 14),
        // Half rows only, whole columns sheared; every pixel measures both bands.
        (2, shares_of((3.0 / 3.1, 3.0 / 3.04), [0, 0, 1], [-1, 0, 1]), HalfViews { rows: 0b101, cols: 0 }, 99),
    ] {
        let (mut m, rows, y) = measure_half(&shares, half, per_band, 60 + case, None);
        assert_eq!(m.count(), rows.len());
        let half_row = |e: usize| half.rows >> (e / B / PV % PU) & 1 != 0;
        assert!(
            rows.iter().any(|(_, t)| t.iter().filter(|&&(e, _)| half_row(e)).count() >= 2),
            "case {case}: no measurement reads a half view's two positions"
        );
        // A value at the last grid position of half view row 0: no cell in the patch.
        let gone = Shape::index(PS - 1, 0, 0, 1, 0);
        if m.get(gone).is_none() {
            m.set(gone, 0.75).unwrap();
        }
        let (a, w) = dense(&rows, &kd, n);
        let mut r = rng(70 + case);
        let y = DVector::from_vec(y);
        let mut sums = RowSums::new();
        let exact = Ball::new(0.0, 0.0, m.count() as u32, 0);
        let mut scratch = [0.0f32; N];
        for step in 0..2 {
            let s0: [f32; N] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
            let s = DVector::from_iterator(n, s0.iter().map(|&v| f64::from(v)));
            let want = &s + a.transpose() * (&y - &a * &s).component_div(&w);
            let mut coeffs = s0;
            let before = project_shares(&dict, &mut coeffs, &mut scratch, &m, &exact, &mut sums, None);
            let residual = (&a * &s - &y).norm();
            assert!(
                (f64::from(before) - residual).abs() < 1e-4 * residual.max(1.0),
                "case {case} step {step}: residual"
            );
            let err = coeffs.iter().zip(want.iter()).map(|(&g, w)| (f64::from(g) - w).abs()).fold(0.0, f64::max);
            assert!(err < 5e-5, "case {case} step {step}: differs from the dense step by {err}");
        }
        let x: [f32; N] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
        let mut predicted = x;
        to_sensor::<Shape>(&m, &mut predicted, &mut scratch);
        for (entry, row) in &rows {
            let want: f64 = row.iter().map(|&(e, w)| w * f64::from(x[e])).sum();
            assert!((f64::from(predicted[*entry]) - want).abs() < 1e-5, "case {case}: prediction at {entry}");
        }
        assert_eq!(predicted[gone], x[gone], "case {case}: the last position of a half view was predicted");
    }
}

/// Every pixel measures both bands and sits half a cell off its cell's centre (less one
/// place unit), the same phase everywhere: `M M^T`'s diagonal is about a quarter of its
/// rows' sums away from the patch's edges. Twenty steps by the rows' sums shrink the residual (in the `W^-1` norm, where
/// the scaled `M M^T` has every eigenvalue in `(0, 1]`); by the diagonal alone, the same
/// steps grow it (checked on the dense definition, so the test shows why the sums).
#[test]
fn on_a_band_measured_everywhere_the_residual_shrinks() {
    let dict = random_dictionary::<PatchShape<PS, PT, PU, PV, B, N>>(6);
    let (kd, n) = dense_kronecker(dict.synthesis());
    let shares = shares_of((1.0, 1.0), [0; 3], [0; 3]);
    let (m, rows, y) = measure(&shares, PS * PT * PU * PV, 21, Some(126.0 / f64::from(PLACE_UNIT)));
    let (a, w) = dense(&rows, &kd, n);
    let y = DVector::from_vec(y);
    let norm = |c: &DVector<f64>| (&a * c - &y).component_div(&w.map(f64::sqrt)).norm();
    let mut r = rng(3);
    let s0: [f32; N] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
    let mut coeffs = s0;
    let mut scratch = [0.0f32; N];
    let start = DVector::from_iterator(n, s0.iter().map(|&v| f64::from(v)));
    let mut last = norm(&start);
    let mut sums = RowSums::new();
    for step in 0..20 {
        project_shares(
            &dict,
            &mut coeffs,
            &mut scratch,
            &m,
            &Ball::new(0.0, 0.0, m.count() as u32, 0),
            &mut sums,
            None,
        );
        let now = norm(&DVector::from_iterator(n, coeffs.iter().map(|&v| f64::from(v))));
        assert!(now <= last * (1.0 + 1e-4), "step {step}: residual {last} grew to {now}");
        last = now;
    }
    assert!(last < 0.5 * norm(&start), "residual {} from {}", last, norm(&start));
    let g = &a * a.transpose();
    let diagonal = g.diagonal();
    let mut plain = start.clone();
    for _ in 0..20 {
        plain = &plain + a.transpose() * (&y - &a * &plain).component_div(&diagonal);
    }
    assert!(norm(&plain) > 10.0 * norm(&start), "the diagonal's steps did not diverge: {}", norm(&plain));
}

/// `Reach::outside` is the share of the definition's box that lies over cells outside the
/// patch (`1 -` the inside parts of the two axes multiplied), for every pixel of patches
/// unsheared and sheared both ways, pixels narrower and wider than a cell, at random places;
/// sheared, some pixel reaches further outside than unsheared (the micro-image borders the
/// shear moves apart: what it is for).
#[test]
fn the_share_outside_the_patch_is_the_definitions() {
    let mut r = rng(66);
    for (width, rows, cols) in [
        ((1.008f32, 1.02f32), [0i8, 0, 0], [0i8, 0, 0]),
        ((1.02, 0.9), [1, 0, -1], [0, 0, 0]),
        ((0.8, 1.25), [-1, 0, 1], [1, 0, -1]),
    ] {
        let shares = shares_of(width, rows, cols);
        let reach = Reach::<Shape>::new(&shares, HalfViews::NONE);
        let unsheared = Reach::<Shape>::new(&CellShares::unsheared(width), HalfViews::NONE);
        let mut further = false;
        for (s, t, u, v) in (0..PS)
            .flat_map(|s| (0..PT).flat_map(move |t| (0..PU).flat_map(move |u| (0..PV).map(move |v| (s, t, u, v)))))
        {
            let place = (r.random_range(-0.5f64..0.5), r.random_range(-0.5f64..0.5));
            let p = (s as i64 + i64::from(shares.shift.0[u])) * PU as i64 + u as i64;
            let q = (t as i64 + i64::from(shares.shift.1[v])) * PV as i64 + v as i64;
            let inside = |cells: [f64; 3], at: i64, views: usize, len: usize, shift: &[i8]| {
                cells[1]
                    + [(0usize, -1i64), (2, 1)]
                        .iter()
                        .filter(|&&(_, d)| find(at + d, views, len, shift).is_some())
                        .map(|&(k, _)| cells[k])
                        .sum::<f64>()
            };
            let ir = inside(box_1d(p as f64 + 0.5 + place.0, p, f64::from(width.0)), p, PU, PS, &shares.shift.0);
            let ic = inside(box_1d(q as f64 + 0.5 + place.1, q, f64::from(width.1)), q, PV, PT, &shares.shift.1);
            let want = 1.0 - ir * ic;
            let got = f64::from(reach.outside((s, t, u, v), (place.0 as f32, place.1 as f32)));
            assert!((got - want).abs() < 1e-5, "{shares:?} pixel {:?} at {place:?}: {got} vs {want}", (s, t, u, v));
            // Each cell outside, by its share of the square: the definition's box over the
            // cells around the pixel's own, those not found in the patch.
            let (br, bc) = (
                box_1d(p as f64 + 0.5 + place.0, p, f64::from(width.0)),
                box_1d(q as f64 + 0.5 + place.1, q, f64::from(width.1)),
            );
            let mut cells = Vec::new();
            reach.outside_cells((s, t, u, v), (place.0 as f32, place.1 as f32), |d, w| cells.push((d, f64::from(w))));
            let mut expected = Vec::new();
            for (i, dr) in (-1i64..=1).enumerate() {
                for (j, dc) in (-1i64..=1).enumerate() {
                    let out = find(p + dr, PU, PS, &shares.shift.0).is_none()
                        || find(q + dc, PV, PT, &shares.shift.1).is_none();
                    if out && br[i] * bc[j] > 0.0 {
                        expected.push(((dr as isize, dc as isize), br[i] * bc[j]));
                    }
                }
            }
            assert_eq!(cells.len(), expected.len(), "{shares:?} pixel {:?}: {cells:?} vs {expected:?}", (s, t, u, v));
            for ((d, w), (e, x)) in cells.iter().zip(&expected) {
                assert!(
                    d == e && (w - x).abs() < 1e-5,
                    "{shares:?} pixel {:?}: {cells:?} vs {expected:?}",
                    (s, t, u, v)
                );
            }
            let total: f64 = cells.iter().map(|(_, w)| w).sum();
            assert!((total - got).abs() < 1e-5, "{shares:?}: the cells outside sum to {total}, the reach {got}");
            further |= got > f64::from(unsheared.outside((s, t, u, v), (place.0 as f32, place.1 as f32))) + 1e-3;
        }
        let sheared = rows != [0; 3] || cols != [0; 3];
        assert_eq!(further, sheared, "{shares:?}: a pixel further outside than unsheared");
    }
}

/// A noise ball weighted by each measurement's variance (shot noise: it grows with the
/// value): the step reading the solve's table of weights (`projection::weigh`, what a
/// descent passes) moves the patch to the same bits as the step computing each weight,
/// and both move it by less than the exact projection (the ball's surface, not its
/// centre). Fails if the table were read at another entry than the measurement's.
#[test]
fn a_weighted_ball_reads_its_weights_from_the_table_to_the_same_bits() {
    let dict = random_dictionary::<PatchShape<PS, PT, PU, PV, B, N>>(7);
    for (case, shares, per_band) in [
        (0u64, shares_of((3.0 / 3.06, 3.0 / 3.06), [0; 3], [0; 3]), 20),
        (1, shares_of((3.0 / 3.1, 3.0 / 3.02), [1, 0, -1], [-1, 0, 1]), 30),
    ] {
        let (mut m, _, _) = measure(&shares, per_band, 40 + case, None);
        // Positive values, unequal gains: every weight its own.
        for e in 0..N {
            if let Some(v) = m.get(e) {
                m.set(e, 0.2 + v.abs()).unwrap();
            }
        }
        m.set_gains(&[0.7, 1.9]).unwrap();
        let ball = Ball::new(0.01, 0.02, m.count() as u32, 0);
        assert!(ball.is_weighted());
        let mut table = [0.0f32; N];
        weigh::<Shape>(&m, &ball, &mut table);
        let mut r = rng(50 + case);
        let s0: [f32; N] = core::array::from_fn(|_| r.random_range(-1.0f32..1.0));
        let mut scratch = [0.0f32; N];
        let (mut computed, mut read, mut exact) = (s0, s0, s0);
        let mut sums = RowSums::new();
        let n0 = project_shares(&dict, &mut computed, &mut scratch, &m, &ball, &mut sums, None);
        let mut sums = RowSums::new();
        let n1 = project_shares(&dict, &mut read, &mut scratch, &m, &ball, &mut sums, Some(&table));
        assert_eq!(n0.to_bits(), n1.to_bits(), "case {case}: residual norms");
        assert!(computed.iter().zip(&read).all(|(a, b)| a.to_bits() == b.to_bits()), "case {case}: the moves differ");
        let mut sums = RowSums::new();
        project_shares(&dict, &mut exact, &mut scratch, &m, &Ball::new(0.0, 0.0, m.count() as u32, 0), &mut sums, None);
        let dist = |x: &[f32; N]| x.iter().zip(&s0).map(|(a, b)| (a - b) * (a - b)).sum::<f32>();
        assert!(
            dist(&read) > 0.0 && dist(&read) < dist(&exact),
            "case {case}: the ball's move is not short of the exact one"
        );
    }
}

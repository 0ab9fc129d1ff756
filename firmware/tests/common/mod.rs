//! Slow, obvious references shared by the firmware's tests.
#![allow(dead_code)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use slf_firmware::PaperShape;
use slf_firmware::Shape;
use slf_firmware::dictionary::{Factors, Matrix};
use slf_firmware::mode::{Mode, ModeMatrix};
use slf_firmware::{Array, Fixed};
use slf_firmware::{Dictionary, Mask, PatchShape, Workspace};

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// The rows of a random orthonormal `d x d` matrix: Gram-Schmidt in f64 on a Gaussian-ish
/// matrix.
fn gram_schmidt(d: usize, rng: &mut ChaCha8Rng) -> Vec<Vec<f64>> {
    let mut rows: Vec<Vec<f64>> = Vec::new();
    while rows.len() < d {
        let mut v = vec![0.0f64; d];
        for x in v.iter_mut() {
            *x = rng.random_range(-1.0..1.0);
        }
        for _ in 0..2 {
            for r in &rows {
                let dot: f64 = r.iter().zip(&v).map(|(a, b)| a * b).sum();
                for (x, a) in v.iter_mut().zip(r) {
                    *x -= dot * a;
                }
            }
        }
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if n > 1e-3 {
            rows.push(v.iter().map(|x| x / n).collect());
        }
    }
    rows
}

/// A random orthonormal `D x D` matrix ([`gram_schmidt`]).
pub fn random_orthonormal<const D: usize>(rng: &mut ChaCha8Rng) -> Matrix<D> {
    random_mode::<Fixed<D>>(rng)
}

/// A random orthonormal matrix of mode `E` ([`gram_schmidt`]).
pub fn random_mode<E: Mode>(rng: &mut ChaCha8Rng) -> ModeMatrix<E> {
    let rows = gram_schmidt(E::D, rng);
    let mut m = E::ZERO_MATRIX;
    for (mr, r) in m.iter_mut().zip(&rows) {
        for (a, b) in mr.iter_mut().zip(r) {
            *a = *b as f32;
        }
    }
    m
}

pub fn random_dictionary<S: Shape>(seed: u64) -> Dictionary<S> {
    let mut r = rng(seed);
    Dictionary::new(Factors {
        m1: random_mode::<S::S>(&mut r),
        m2: random_mode::<S::T>(&mut r),
        m3: random_mode::<S::U>(&mut r),
        m4: random_mode::<S::V>(&mut r),
        m5: random_mode::<S::Bands>(&mut r),
    })
    .expect("Gram-Schmidt output is orthonormal")
}

fn flat<E: Mode>(m: &ModeMatrix<E>) -> Vec<f64> {
    m.iter().flat_map(|r| r.iter()).map(|&x| f64::from(x)).collect()
}

/// The dense N x N matrix of a separable operator, in f64: row-major vec of the patch layout
/// (band fastest), so `K = M1 (x) M2 (x) M3 (x) M4 (x) M5` by the Kronecker product.
pub fn dense_kronecker<S: Shape>(f: &Factors<S>) -> (Vec<f64>, usize) {
    fn kron(a: &[f64], ad: usize, b: &[f64], bd: usize) -> Vec<f64> {
        let d = ad * bd;
        let mut k = vec![0.0; d * d];
        for i in 0..ad {
            for j in 0..ad {
                let x = a[i * ad + j];
                for p in 0..bd {
                    for q in 0..bd {
                        k[(i * bd + p) * d + j * bd + q] = x * b[p * bd + q];
                    }
                }
            }
        }
        k
    }
    let k = kron(&flat::<S::S>(&f.m1), S::PS, &flat::<S::T>(&f.m2), S::PT);
    let k = kron(&k, S::PS * S::PT, &flat::<S::U>(&f.m3), S::PU);
    let k = kron(&k, S::PS * S::PT * S::PU, &flat::<S::V>(&f.m4), S::PV);
    let k = kron(&k, S::PS * S::PT * S::PU * S::PV, &flat::<S::Bands>(&f.m5), S::B);
    (k, S::PS * S::PT * S::PU * S::PV * S::B)
}

/// `y = K x` in f64.
pub fn dense_apply(k: &[f64], n: usize, x: &[f32]) -> Vec<f64> {
    (0..n).map(|i| k[i * n..(i + 1) * n].iter().zip(x).map(|(a, &b)| a * f64::from(b)).sum()).collect()
}

pub fn rel_err(a: &[f32], reference: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(reference).map(|(&x, y)| (f64::from(x) - y).powi(2)).sum();
    let den: f64 = reference.iter().map(|y| y * y).sum();
    (num / den.max(1e-300)).sqrt()
}

pub fn rel_err32(a: &[f32], reference: &[f32]) -> f64 {
    let r: Vec<f64> = reference.iter().map(|&x| f64::from(x)).collect();
    rel_err(a, &r)
}

pub fn max_abs_diff(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

/// A smooth, positive, natural-ish patch: low-order trends in every dimension plus a
/// little texture, in [0.05, 0.95].
pub fn smooth_patch<S: Shape>(seed: u64) -> Vec<f32> {
    let mut r = rng(seed);
    let c: [f32; 8] = core::array::from_fn(|_| r.random_range(-1.0..1.0));
    let mut x = vec![0.0f32; S::N];
    for (i, v) in x.iter_mut().enumerate() {
        let [s, t, u, v_, b] = S::coordinates(i);
        let (s, t, u, vv, b) = (
            s as f32 / S::PS as f32,
            t as f32 / S::PT as f32,
            u as f32 / S::PU as f32,
            v_ as f32 / S::PV as f32,
            b as f32 / S::B as f32,
        );
        let val = 0.5
            + 0.15 * c[0] * s
            + 0.15 * c[1] * t
            + 0.03 * c[2] * u
            + 0.03 * c[3] * vv
            + 0.2 * c[4] * (3.0 * b).sin()
            + 0.05 * c[5] * (s * t * 6.0).cos()
            + 0.02 * c[6] * r.random_range(-1.0f32..1.0);
        *v = val.clamp(0.05, 0.95);
    }
    x
}

/// Fills `ws`'s measurements as the camera would: patch pixel `(s, t, u, v)` of the patch
/// whose first lenslet is `lenslet_origin` sees `mask`'s bands at its sensor pixel.
pub fn measure<S: Shape>(mask: &Mask, lenslet_origin: (usize, usize), truth: &[f32], ws: &mut Workspace<S>) {
    measure_window(mask, lenslet_origin, (0, 0), truth, ws);
}

/// [`measure`] for the angular window whose first view is `view_origin`.
pub fn measure_window<S: Shape>(
    mask: &Mask,
    lenslet_origin: (usize, usize),
    view_origin: (usize, usize),
    truth: &[f32],
    ws: &mut Workspace<S>,
) {
    let l = mask.lenslet_size();
    let (lu, lv) = (l.rows as usize, l.cols as usize);
    let m = ws.measurements_mut();
    m.clear();
    for s in 0..S::PS {
        for t in 0..S::PT {
            for u in 0..S::PU {
                for v in 0..S::PV {
                    let row = (lenslet_origin.0 + s) * lu + view_origin.0 + u;
                    let col = (lenslet_origin.1 + t) * lv + view_origin.1 + v;
                    for &band in mask.bands_at(row, col).iter() {
                        let i = S::index(s, t, u, v, band as usize);
                        m.set(i, truth[i]).expect("finite truth");
                    }
                }
            }
        }
    }
}

/// The sheared-patch tests' small sensor: patches of 3 x 3 lenslets x 2 x 2 views x 4
/// bands on lenslets of 3 x 3 views (centre view 1), so a dense 144 x 144 basis is cheap.
pub const L3: slf_firmware::LensletSize = slf_firmware::LensletSize { rows: 3, cols: 3 };
pub const SMALL: slf_firmware::SensorGeometry = slf_firmware::SensorGeometry { lenslets: (10, 11), lenslet: L3 };
pub type Small<'a> = slf_firmware::TileDecoder<'a, PatchShape<3, 3, 2, 2, 4, 144>>;
pub type SmallShape = PatchShape<3, 3, 2, 2, 4, 144>;

/// Raw samples `x + 10` read back as `x` (any sign), up to f32 rounding near 10.
pub const OFFSET: slf_firmware::RawFormat = slf_firmware::RawFormat { black: 10.0, white: 11.0, max_valid: 1e6 };

/// The small sensor's decoder (every patch solved: `min_bands` 0).
pub fn small_decoder(mask: Mask<'static>) -> Small<'static> {
    Small::new(slf_firmware::DecoderConfig {
        sensor: SMALL,
        mask,
        raw: OFFSET,
        defects: slf_firmware::DefectList::EMPTY,
        sl0: slf_firmware::Sl0Config { min_bands: 0, ..slf_firmware::Sl0Config::DEFAULT },
    })
    .unwrap()
}

/// An ensemble blob of `members`, leaked for the `'static` an [`slf_firmware::Ensemble`]
/// borrows.
pub fn blob(members: &[Dictionary<PaperShape>]) -> &'static [u8] {
    let mut out = vec![0u8; slf_firmware::blob::blob_len([5, 5, 4, 4, 13], members.len())];
    slf_firmware::blob::write_blob(members, &mut out).unwrap();
    Box::leak(out.into_boxed_slice())
}

/// A patch of 15 atoms of `dict` (a member's exactly sparse patch).
pub fn sparse_in(dict: &Dictionary<PaperShape>, seed: u64) -> Vec<f32> {
    let mut r = rng(seed);
    let mut s = Box::new([0.0f32; 5200]);
    for _ in 0..15 {
        s[r.random_range(0..5200)] = r.random_range(1.0f32..3.0) * if r.random_bool(0.5) { 1.0 } else { -1.0 };
    }
    let mut x = Box::new([0.0f32; 5200]);
    slf_firmware::transform::synthesize(dict, &mut s, &mut x);
    x.to_vec()
}

/// A decoder config of `lenslets` lenslets of 5 x 5 views through `mask`: normalised raw
/// samples, no defects, the default solver.
pub fn decoder_config(lenslets: (u16, u16), mask: Mask<'static>) -> slf_firmware::DecoderConfig<'static> {
    slf_firmware::DecoderConfig {
        sensor: slf_firmware::SensorGeometry { lenslets, lenslet: slf_firmware::LensletSize { rows: 5, cols: 5 } },
        mask,
        raw: slf_firmware::RawFormat::NORMALISED,
        defects: slf_firmware::DefectList::EMPTY,
        sl0: slf_firmware::Sl0Config::DEFAULT,
    }
}

/// Every accepted patch of the paper's shape, with its origin and report.
#[derive(Default)]
pub struct Patches(pub Vec<(slf_firmware::PatchOrigin, Vec<f32>, slf_firmware::PatchReport)>);

impl slf_firmware::PatchSink<PaperShape> for Patches {
    type Error = ();
    fn accept(
        &mut self,
        o: slf_firmware::PatchOrigin,
        patch: &[f32; 5200],
        r: &slf_firmware::PatchReport,
    ) -> Result<(), ()> {
        self.0.push((o, patch.to_vec(), *r));
        Ok(())
    }
}

/// 10 x 15 lenslets of 5 x 5 views (13 bands, lenslet-major, band fastest): smooth in the left third, rougher to the right (texture at the
/// lenslet scale whose amplitude grows with the column).
pub fn rough_light_field(seed: u64) -> Vec<f32> {
    let mut r = rng(seed);
    let (s, t) = (10, 15);
    let rough: Vec<f32> = (0..s * t * 13).map(|_| r.random_range(-1.0..1.0)).collect();
    let mut l = vec![0.0; s * t * 25 * 13];
    for (i, x) in l.iter_mut().enumerate() {
        let b = i % 13;
        let tt = (i / 325) % t;
        let ss = i / (325 * t);
        let amplitude = 0.25 * (tt / 5) as f32 / 2.0;
        *x = 0.4 + 0.1 * ((b as f32) * 0.4).cos() + amplitude * rough[(ss * t + tt) * 13 + b];
    }
    l
}

/// The raw frames of [`rough_light_field`] through `mask`, one a snapshot (50 x 75 pixels).
pub fn capture_10x15(l: &[f32], mask: &Mask) -> Vec<Vec<f32>> {
    (0..mask.snapshots())
        .map(|j| {
            (0..50 * 75)
                .map(|p| {
                    let (row, col) = (p / 75, p % 75);
                    let b = mask.band(j, row, col).unwrap() as usize;
                    l[(((((row / 5) * 15) + col / 5) * 5 + row % 5) * 5 + col % 5) * 13 + b]
                })
                .collect()
        })
        .collect()
}

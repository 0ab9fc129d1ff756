//! Training a learned 5D dictionary ensemble (AMDE-style) from light-field patches.
//!
//! K members, each five orthonormal matrices (5x5, 5x5, PUxPU, PVxPV, 13x13), for the paper's
//! patch (4 x 4 views) or the full-view patch (5 x 5; `slf train --patch-views`):
//!
//! 1. **Initialise** each member from the HOSVD of a small random group of patches (a few
//!    dozen): per mode, the eigenvectors of the summed mode-unfolding Gram matrix. Small
//!    random groups make the members differ; a partition of all patches makes them alike.
//! 2. **Code** every patch in every member with its `tau` largest coefficients; the coding
//!    error is the energy of the rest (the members are orthonormal).
//! 3. **Assign** each patch to the member with the least error at `tau`; drop members that
//!    code no patch.
//! 4. **Update** each mode of each member by orthogonal Procrustes on the mode unfolding of
//!    its patches, with the sparse codes fixed: minimise `sum ||X - S x_i U_i||` over an
//!    orthonormal `U_n`: `M = U_n G`, `G = sum S_full(n) S_sparse(n)^T`, `U_n <- A B^T` for
//!    `M = A Sigma B^T` (a small SVD, nalgebra). Then re-code. Neither step can increase
//!    the coding error at fixed assignments; a test holds it to that.
//!
//! With `dct_member` (the default) member 0 is the 5D DCT, never updated or dropped: the
//! learned members come from textured training scenes, and a smooth patch is coded best by
//! the DCT, so the ensemble keeps it as one of its choices.
//!
//! Parallel over patches (rayon) in fixed chunks summed in order, so the result does not
//! depend on the thread count: the same seed and patches give the same blob bytes.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use nalgebra::{DMatrix, SymmetricEigen};
use rand::seq::index::sample;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use slf_firmware::Dictionary;
use slf_firmware::Shape;
use slf_firmware::dictionary::Factors;
use slf_firmware::transform::analyze;

use crate::decode::cs::PatchViews;
use crate::io::lightfield::LightField;
use crate::io::patch::{BANDS, HostDictionary, HostShape, LENSLETS};

/// The patch's mode sizes.
const fn dims<const PU: usize, const PV: usize>() -> [usize; 5] {
    [LENSLETS, LENSLETS, PU, PV, BANDS]
}
const CHUNK: usize = 64;

/// Training parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrainConfig {
    /// Members K.
    pub members: usize,
    /// Coefficients kept per patch when coding.
    pub tau: usize,
    /// Alternations of coding, assignment and update.
    pub iterations: usize,
    /// Patches per member for the HOSVD initialisation.
    pub group: usize,
    pub seed: u64,
    /// Member 0 is the 5D DCT, kept fixed: patches the DCT codes best (smooth ones) keep it.
    pub dct_member: bool,
    /// Show a progress bar.
    pub progress: bool,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self { members: 8, tau: 100, iterations: 10, group: 32, seed: 1, dct_member: true, progress: false }
    }
}

/// Coding error of one iteration, mean over patches of the relative error
/// `||X - X_tau||^2 / ||X||^2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationReport {
    pub ensemble_error: f64,
    pub dct_error: f64,
    pub members: usize,
}

/// Patches sampled uniformly from light fields: `count` patches of 5 x 5 lenslets x `PU x PV`
/// views x 13 bands at random positions and angular windows, flat in the patch layout.
pub fn sample_patches<const PU: usize, const PV: usize, const N: usize>(
    fields: &[LightField],
    count: usize,
    seed: u64,
) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(count * N);
    for _ in 0..count {
        let lf = &fields[rng.random_range(0..fields.len())];
        let (r, c) = (rng.random_range(0..=lf.rows - 5), rng.random_range(0..=lf.cols - 5));
        let (u0, v0) = (rng.random_range(0..=lf.views.0 - PU), rng.random_range(0..=lf.views.1 - PV));
        for i in 0..N {
            let [s, t, u, v, b] = HostShape::<PU, PV, N>::coordinates(i);
            out.push(lf.get(u0 + u, v0 + v, r + s, c + t, b));
        }
    }
    out
}

/// One member's matrices in f64 (synthesis: columns are atoms), row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Member(pub [Vec<f64>; 5]);

impl Member {
    /// The f32 dictionary (checked orthonormal by the firmware).
    pub fn dictionary<const PU: usize, const PV: usize, const N: usize>(&self) -> HostDictionary<PU, PV, N> {
        fn m<const D: usize>(v: &[f64]) -> [[f32; D]; D] {
            core::array::from_fn(|i| core::array::from_fn(|j| v[i * D + j] as f32))
        }
        let f = Factors {
            m1: m::<5>(&self.0[0]),
            m2: m::<5>(&self.0[1]),
            m3: m::<PU>(&self.0[2]),
            m4: m::<PV>(&self.0[3]),
            m5: m::<BANDS>(&self.0[4]),
        };
        // Procrustes and eigenvectors are orthonormal to ~1e-15 in f64; f32 rounding keeps
        // them within 1e-6, far inside the firmware's 1e-4.
        Dictionary::new(f).unwrap_or_else(|e| panic!("learned member not orthonormal: {e}"))
    }
}

/// Index stride of mode `n` in the patch layout.
fn stride<const PU: usize, const PV: usize>(n: usize) -> usize {
    dims::<PU, PV>()[n + 1..].iter().product()
}

/// `buf x_n R` for a `d x d` matrix `R` (row-major), in place.
fn mode_product<const PU: usize, const PV: usize, const N: usize>(buf: &mut [f32], n: usize, r: &[f64]) {
    let d = dims::<PU, PV>()[n];
    let st = stride::<PU, PV>(n);
    let outer = N / (d * st);
    let mut fibre = vec![0.0f64; d];
    for o in 0..outer {
        for i in 0..st {
            let base = o * d * st + i;
            for (c, f) in fibre.iter_mut().enumerate() {
                *f = f64::from(buf[base + c * st]);
            }
            for a in 0..d {
                buf[base + a * st] = (0..d).map(|c| r[a * d + c] * fibre[c]).sum::<f64>() as f32;
            }
        }
    }
}

/// The HOSVD of a group of patches: per mode, eigenvectors of the summed unfolding Gram.
fn hosvd<const PU: usize, const PV: usize, const N: usize>(patches: &[f32], group: &[usize]) -> Member {
    Member(core::array::from_fn(|n| {
        let (d, st) = (dims::<PU, PV>()[n], stride::<PU, PV>(n));
        let mut gram = DMatrix::<f64>::zeros(d, d);
        for &p in group {
            let x = &patches[p * N..(p + 1) * N];
            for o in 0..N / (d * st) {
                for i in 0..st {
                    let base = o * d * st + i;
                    for a in 0..d {
                        for c in 0..d {
                            gram[(a, c)] += f64::from(x[base + a * st]) * f64::from(x[base + c * st]);
                        }
                    }
                }
            }
        }
        let eig = SymmetricEigen::new(gram);
        let mut order: Vec<usize> = (0..d).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        let mut u = vec![0.0; d * d];
        for (k, &j) in order.iter().enumerate() {
            let col = eig.eigenvectors.column(j);
            // Deterministic sign: the largest entry positive.
            let big = col.iter().fold(0.0f64, |m, &x| if x.abs() > m.abs() { x } else { m });
            let sign = if big < 0.0 { -1.0 } else { 1.0 };
            for i in 0..d {
                u[i * d + k] = sign * col[i];
            }
        }
        u
    }))
}

/// The relative energy outside the `tau` largest magnitudes, and their indices.
pub fn top_tau(s: &[f32], tau: usize) -> (f64, Vec<u16>) {
    let mut idx: Vec<u16> = (0..s.len() as u16).collect();
    let total: f64 = s.iter().map(|&x| f64::from(x) * f64::from(x)).sum();
    if tau < s.len() {
        idx.select_nth_unstable_by(tau, |&a, &b| s[b as usize].abs().total_cmp(&s[a as usize].abs()).then(a.cmp(&b)));
        idx.truncate(tau);
    }
    idx.sort_unstable();
    let kept: f64 = idx.iter().map(|&i| f64::from(s[i as usize]).powi(2)).sum();
    let err = if total > 0.0 { ((total - kept) / total).max(0.0) } else { 0.0 };
    (err, idx)
}

/// Coefficients of patch `p` in `dict`.
fn coefficients<const PU: usize, const PV: usize, const N: usize>(
    patches: &[f32],
    p: usize,
    dict: &HostDictionary<PU, PV, N>,
) -> Box<[f32; N]> {
    let mut x: Box<[f32; N]> = Box::new([0.0; N]);
    x.copy_from_slice(&patches[p * N..(p + 1) * N]);
    let mut s = Box::new([0.0; N]);
    analyze(dict, &mut x, &mut s);
    s
}

/// Mean relative coding error of every patch in `dict` at `tau`.
pub fn coding_error<const PU: usize, const PV: usize, const N: usize>(
    patches: &[f32],
    dict: &HostDictionary<PU, PV, N>,
    tau: usize,
) -> f64 {
    let count = patches.len() / N;
    let sum: f64 =
        (0..count).into_par_iter().map(|p| top_tau(&coefficients::<PU, PV, N>(patches, p, dict)[..], tau).0).sum();
    sum / count as f64
}

/// Mean relative coding error with each patch in its best member: the ensemble's error.
pub fn ensemble_error<const PU: usize, const PV: usize, const N: usize>(
    patches: &[f32],
    members: &[HostDictionary<PU, PV, N>],
    tau: usize,
) -> f64 {
    let count = patches.len() / N;
    let sum: f64 = (0..count)
        .into_par_iter()
        .map(|p| {
            members
                .iter()
                .map(|d| top_tau(&coefficients::<PU, PV, N>(patches, p, d)[..], tau).0)
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    sum / count as f64
}

/// Each patch's best member and its error.
pub fn assign<const PU: usize, const PV: usize, const N: usize>(
    patches: &[f32],
    members: &[HostDictionary<PU, PV, N>],
    tau: usize,
) -> Vec<(usize, f64)> {
    (0..patches.len() / N)
        .into_par_iter()
        .map(|p| {
            members
                .iter()
                .enumerate()
                .map(|(k, d)| (k, top_tau(&coefficients::<PU, PV, N>(patches, p, d)[..], tau).0))
                .fold((0, f64::INFINITY), |best, c| if c.1 < best.1 { c } else { best })
        })
        .collect()
}

/// Mean coding error of the patches assigned to `k` (`assignment[p] == k`) in `member`.
pub fn member_error<const PU: usize, const PV: usize, const N: usize>(
    patches: &[f32],
    member: &Member,
    which: &[usize],
    tau: usize,
) -> f64 {
    let d = member.dictionary::<PU, PV, N>();
    which.iter().map(|&p| top_tau(&coefficients::<PU, PV, N>(patches, p, &d)[..], tau).0).sum::<f64>()
        / which.len().max(1) as f64
}

/// A patch's full coefficients in a member and its fixed sparse code `(index, value)`.
type PatchCode<const N: usize> = (Box<[f32; N]>, Vec<(u16, f32)>);

/// One Procrustes update of every mode of `member` on its patches `which`, codes fixed
/// at the start (the `tau` largest coefficients in the current member).
pub fn update_member<const PU: usize, const PV: usize, const N: usize>(
    patches: &[f32],
    member: &Member,
    which: &[usize],
    tau: usize,
) -> Member {
    let dict = member.dictionary::<PU, PV, N>();
    // Per patch: the full coefficients (kept current as modes change) and the fixed code.
    let mut state: Vec<PatchCode<N>> = which
        .par_iter()
        .map(|&p| {
            let s = coefficients::<PU, PV, N>(patches, p, &dict);
            let (_, idx) = top_tau(&s[..], tau);
            let code = idx.iter().map(|&i| (i, s[i as usize])).collect();
            (s, code)
        })
        .collect();
    let mut next = member.clone();
    for (n, &d) in dims::<PU, PV>().iter().enumerate() {
        let st = stride::<PU, PV>(n);
        // G = sum_p S_full(n) S_sparse(n)^T, in fixed chunks summed in order.
        let parts: Vec<Vec<f64>> = state
            .par_chunks(CHUNK)
            .map(|chunk| {
                let mut g = vec![0.0f64; d * d];
                for (full, code) in chunk {
                    for &(i, v) in code {
                        let i = i as usize;
                        let c = (i / st) % d;
                        let base = i - c * st;
                        for a in 0..d {
                            g[a * d + c] += f64::from(full[base + a * st]) * f64::from(v);
                        }
                    }
                }
                g
            })
            .collect();
        let mut g = DMatrix::<f64>::zeros(d, d);
        for part in &parts {
            for a in 0..d {
                for c in 0..d {
                    g[(a, c)] += part[a * d + c];
                }
            }
        }
        let u_cur = DMatrix::from_row_slice(d, d, &next.0[n]);
        let m = &u_cur * g;
        let svd = m.svd(true, true);
        let (Some(a), Some(bt)) = (svd.u, svd.v_t) else {
            continue;
        };
        let u_new = a * bt;
        // Keep S_full current: S <- S x_n (U_new^T U_cur).
        let r = u_new.transpose() * &u_cur;
        let r_rows: Vec<f64> = (0..d * d).map(|k| r[(k / d, k % d)]).collect();
        state.par_iter_mut().for_each(|(full, _)| mode_product::<PU, PV, N>(&mut full[..], n, &r_rows));
        next.0[n] = (0..d * d).map(|k| u_new[(k / d, k % d)]).collect();
    }
    next
}

/// The starting members: the fixed DCT (with `dct_member`), then the HOSVD of a random
/// group of `group` patches each.
pub fn init_members<const PU: usize, const PV: usize, const N: usize>(
    patches: &[f32],
    cfg: &TrainConfig,
) -> Vec<Member> {
    let count = patches.len() / N;
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let fixed = usize::from(cfg.dct_member && cfg.members > 0);
    let mut members: Vec<Member> = Vec::with_capacity(cfg.members);
    if fixed == 1 {
        let dct: Vec<Vec<f64>> =
            crate::decode::paper_1d::Factors::dct_f64_of(dims::<PU, PV>()).0.into_iter().map(|(_, m)| m).collect();
        members.push(Member(dct.try_into().unwrap_or_else(|_| unreachable!("five modes"))));
    }
    while members.len() < cfg.members {
        members.push(hosvd::<PU, PV, N>(patches, &sample(&mut rng, count, cfg.group.min(count)).into_vec()));
    }
    members
}

/// Trains an ensemble on `patches`; returns its members (empty ones dropped) and the
/// coding error per iteration against the DCT's.
pub fn train<const PU: usize, const PV: usize, const N: usize>(
    patches: &[f32],
    cfg: &TrainConfig,
) -> (Vec<HostDictionary<PU, PV, N>>, Vec<IterationReport>) {
    let count = patches.len() / N;
    let fixed = usize::from(cfg.dct_member && cfg.members > 0);
    let mut members = init_members::<PU, PV, N>(patches, cfg);
    let dct_error = coding_error::<PU, PV, N>(patches, &Dictionary::dct(), cfg.tau);
    let bar = progress_bar(cfg.iterations as u64, cfg.progress);
    let mut reports = Vec::new();
    for _ in 0..cfg.iterations {
        let dicts: Vec<HostDictionary<PU, PV, N>> = members.iter().map(Member::dictionary).collect();
        let assignment = assign::<PU, PV, N>(patches, &dicts, cfg.tau);
        let ensemble_error = assignment.iter().map(|a| a.1).sum::<f64>() / count as f64;
        let groups: Vec<Vec<usize>> =
            (0..members.len()).map(|k| (0..count).filter(|&p| assignment[p].0 == k).collect()).collect();
        // Drop members that code no patch (the fixed DCT stays).
        let kept: Vec<(Member, Vec<usize>)> = members
            .into_iter()
            .zip(groups)
            .enumerate()
            .filter(|(k, (_, g))| *k < fixed || !g.is_empty())
            .map(|(_, mg)| mg)
            .collect();
        reports.push(IterationReport { ensemble_error, dct_error, members: kept.len() });
        bar.set_message(format!("ensemble {ensemble_error:.4} vs DCT {dct_error:.4}"));
        members =
            kept.iter()
                .enumerate()
                .map(|(k, (m, g))| {
                    if k < fixed || g.is_empty() {
                        m.clone()
                    } else {
                        update_member::<PU, PV, N>(patches, m, g, cfg.tau)
                    }
                })
                .collect();
        bar.inc(1);
    }
    bar.finish_and_clear();
    (members.iter().map(Member::dictionary).collect(), reports)
}

/// A bar of `iterations` on standard error if `shown`, else hidden.
pub fn progress_bar(iterations: u64, shown: bool) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(iterations), ProgressDrawTarget::hidden());
    if shown {
        bar.set_draw_target(ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("training {bar:40} {pos}/{len} iterations {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
    }
    bar
}

/// `lf` white-balanced as the decoder balances a capture: each band divided by its
/// grey-world gain ([`slf_firmware::gains::gains_from_sums`] over every value), so that
/// members learn the spectra the decoder sees, with the illuminant's tilt taken out.
pub fn white_balanced(lf: &LightField) -> LightField {
    let bands = lf.bands;
    let mut sums = [0.0f64; 13];
    let mut counts = [0u32; 13];
    if bands != 13 {
        return lf.clone();
    }
    for (i, &x) in lf.data.iter().enumerate() {
        sums[i % 13] += f64::from(x);
        counts[i % 13] += 1;
    }
    let gains = slf_firmware::gains::gains_from_sums(&sums.map(|s| s as f32), &counts);
    let mut out = lf.clone();
    for (i, x) in out.data.iter_mut().enumerate() {
        *x /= gains[i % 13];
    }
    out
}

/// Which scene generator training renders.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Generator {
    /// `scene::random`: fronto-parallel cards of chart colours and narrow bands under D65
    /// (the first shipped ensemble's training data).
    Toy,
    /// `realistic::realistic`: slanted and curved surfaces, 1/f textures, measured
    /// reflectances, five illuminants, highlights.
    #[default]
    Realistic,
}

/// Checks, before anything is rendered, that `scenes` training scenes of `size` x `size`
/// pixels a view and `patches` patches fit the memory cap ([`crate::io::budget`]): the
/// scenes twice (rendered, then white-balanced) and the patches twice (sampled, then the
/// trainer's own copy) at the full-view patch's 8,125 values. Before, `slf train-schedule
/// --scenes 3 --size 1024` ran out of memory after 90 s.
///
/// # Errors
/// A scene too large to render, or the estimate above the cap, with the flags to change.
pub fn check_training_memory(scenes: usize, size: usize, patches: usize) -> anyhow::Result<()> {
    crate::sim::scene::SceneSize { views: (5, 5), rows: size, cols: size }.check()?;
    let scene = 25 * (size as u64).pow(2) * 13 * 4;
    let need = 2 * scenes as u64 * scene + 2 * patches as u64 * 8125 * 4;
    crate::io::budget::check(
        need,
        &format!("training on {scenes} scenes of {size} x {size} pixels a view and {patches} patches"),
        "fewer --scenes, a smaller --size or fewer --patches",
    )
}

/// Random light fields for training (seeds `seed..seed + count`; the named scenes of
/// either generator use seeds below 1000, and `slf train` starts at 1000 + its seed), of
/// `size` x `size` pixels a view and 5 x 5 views (their memory checked first:
/// [`check_training_memory`]).
pub fn training_fields(count: usize, size: usize, seed: u64, generator: Generator) -> Vec<LightField> {
    let size = crate::sim::scene::SceneSize { views: (5, 5), rows: size, cols: size };
    (0..count as u64)
        .into_par_iter()
        .map(|i| match generator {
            Generator::Toy => crate::sim::scene::random(seed + i).render(size),
            Generator::Realistic => crate::sim::realistic::realistic(seed + i).render(size),
        })
        .collect()
}

/// `slf train`: samples `patches` patches of `views` from `fields`, trains, prints the coding
/// error per iteration as a markdown table, and writes the ensemble as a blob to `output`.
///
/// # Errors
/// A light field too small for the patch, or an unwritable `output`.
pub fn train_blob(
    fields: &[LightField],
    patches: usize,
    views: PatchViews,
    cfg: &TrainConfig,
    output: &std::path::Path,
) -> anyhow::Result<()> {
    match views {
        PatchViews::Four => train_blob_of::<4, 4, 5200>(fields, patches, cfg, output),
        PatchViews::Five => train_blob_of::<5, 5, 8125>(fields, patches, cfg, output),
    }
}

fn train_blob_of<const PU: usize, const PV: usize, const N: usize>(
    fields: &[LightField],
    patches: usize,
    cfg: &TrainConfig,
    output: &std::path::Path,
) -> anyhow::Result<()> {
    let start = std::time::Instant::now();
    for (i, f) in fields.iter().enumerate() {
        anyhow::ensure!(
            f.bands == 13 && f.views.0 >= PU && f.views.1 >= PV && f.rows >= 5 && f.cols >= 5,
            "training light field {i} is too small for 5x5x{PU}x{PV}x13 patches: {:?}",
            f.shape()
        );
    }
    anyhow::ensure!(cfg.tau <= N, "--tau {}: at most {N}, the values of a 5x5x{PU}x{PV}x13 patch", cfg.tau);
    let data = sample_patches::<PU, PV, N>(fields, patches, cfg.seed);
    let (dicts, reports) = train::<PU, PV, N>(&data, cfg);
    outln!("| iteration | members | ensemble coding error | DCT coding error |\n| --- | --- | --- | --- |")?;
    for (i, r) in reports.iter().enumerate() {
        outln!("| {} | {} | {:.5} | {:.5} |", i + 1, r.members, r.ensemble_error, r.dct_error)?;
    }
    let tau = cfg.tau;
    let final_err = ensemble_error::<PU, PV, N>(&data, &dicts, tau);
    outln!(
        "final: {} members, coding error {final_err:.5} vs DCT {:.5} (tau {tau}, relative energy)",
        dicts.len(),
        reports.first().map_or(0.0, |r| r.dct_error)
    )?;
    let mut blob = vec![0u8; slf_firmware::blob::blob_len(dims::<PU, PV>(), dicts.len())];
    slf_firmware::blob::write_blob(&dicts, &mut blob).map_err(|e| anyhow::anyhow!("{e}"))?;
    crate::io::output::write_bytes(output, &blob)?;
    outln!("wrote {} ({} bytes) in {:.1} s", output.display(), blob.len(), start.elapsed().as_secs_f64())?;
    Ok(())
}

//! The schedule trainer's gradients against finite differences, and a trained schedule
//! against the hand-set one on held-out patches.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use slf_firmware::Dictionary;
use slf_firmware::FullViewShape;
use slf_host::train::schedule::{self, Params, Problem, ScheduleConfig};
use slf_host::train::{self, Generator};

const N: usize = 8125;

fn problems(count: usize, seed: u64) -> Vec<Problem<N>> {
    let fields: Vec<_> =
        train::training_fields(2, 12, 500 + seed, Generator::Realistic).iter().map(train::white_balanced).collect();
    let patches = train::sample_patches::<5, 5, N>(&fields, count, seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    patches.chunks_exact(N).map(|t| Problem::new(t, &schedule::random_pattern::<5, 5, N>(&mut rng))).collect()
}

fn loss(dict: &Dictionary<FullViewShape>, params: &Params<5, 5>, p: &Problem<N>, start: &[f32]) -> f64 {
    let s = params.schedule().unwrap();
    schedule::loss_and_gradient(dict, params, &s, p, start).0
}

#[test]
fn gradients_match_finite_differences() {
    let dict = Dictionary::<FullViewShape>::dct();
    let p = &problems(1, 7)[0];
    let zero_filled: Vec<f32> = (0..N).map(|i| p.measurements.get(i).unwrap_or(0.0)).collect();
    let start = schedule::start(&dict, p, &zero_filled);
    let mut params = Params::<5, 5>::geometric(6, 0.5, 1e-3);
    // Away from the symmetric start: mu and weights differ per step and index.
    params.mu_logit = vec![0.3, -0.2, 0.1, 0.5, -0.4, 0.2];
    params.log_weights[4][3] = 0.4;
    params.log_weights[2][1] = -0.3;
    let (_, grad) = schedule::loss_and_gradient(&dict, &params, &params.schedule().unwrap(), p, &start);
    // Central differences in f64 of an f32 solve: a step of 1e-2 on the log / logit scale.
    let h = 1e-2f32;
    let mut checked = 0;
    let probe = |i: usize, params: &Params<5, 5>| -> f64 {
        let set = |d: f32| {
            let mut q = params.clone();
            match i {
                i if i < 6 => q.log_sigma[i] += d,
                i if i < 12 => q.mu_logit[i - 6] += d,
                12 => q.log_weights[4][3] += d,
                _ => q.log_weights[2][1] += d,
            }
            q
        };
        (loss(&dict, &set(h), p, &start) - loss(&dict, &set(-h), p, &start)) / (2.0 * f64::from(h))
    };
    let analytic = |i: usize| match i {
        i if i < 12 => grad[i],
        12 => grad[12 + 5 + 5 + 5 + 5 + 3],
        _ => grad[12 + 5 + 5 + 1],
    };
    // Absolute slack: f32 rounding of the loss, a thousandth of the largest gradient.
    let slack = 1e-3 * grad.iter().fold(0.0f64, |m, g| m.max(g.abs()));
    for i in 0..14 {
        let (num, ana) = (probe(i, &params), analytic(i));
        let scale = num.abs().max(ana.abs()).max(1e-9);
        assert!(
            (num - ana).abs() <= 0.02 * scale + slack,
            "parameter {i}: finite difference {num:e}, gradient {ana:e}"
        );
        checked += 1;
    }
    assert_eq!(checked, 14);
}

#[test]
fn training_lowers_the_error_on_held_out_patches() {
    let train_set = problems(48, 11);
    let patches: Vec<f32> = train_set.iter().flat_map(|p| p.truth.clone()).collect();
    let cfg =
        ScheduleConfig { cold_steps: 8, warm_steps: 4, patches: 48, iterations: 30, batch: 16, ..Default::default() };
    let dct = Dictionary::<FullViewShape>::dct();
    let dicts = [dct];
    let (trained, report) = schedule::train::<5, 5, N>(&dicts, Some(0), &patches, &cfg).unwrap();
    assert!(report.cold.last < report.cold.first, "{report:?}");
    // Held out: the trained 8 steps against the untrained start of training.
    let held: Vec<_> = problems(24, 12)
        .into_iter()
        .map(|p| {
            let z: Vec<f32> = (0..N).map(|i| p.measurements.get(i).unwrap_or(0.0)).collect();
            let s = schedule::start(&dicts[0], &p, &z);
            (0usize, p, s)
        })
        .collect();
    let before = schedule::mean_error(&dicts, &Params::<5, 5>::geometric(8, 1.0, 1e-4).schedule().unwrap(), &held);
    let after = schedule::mean_error(&dicts, &trained.cold, &held);
    assert!(after < 0.9 * before, "held-out error {after:e} against {before:e} untrained");
}

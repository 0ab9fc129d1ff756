//! PSNR, SSIM and spectral angle against scikit-image on committed fixtures
//! (`fixtures/metrics/make_fixtures.py` made them and `expected.json`), to 1e-4.

use std::path::Path;

use slf_host::eval::metrics::evaluate;
use slf_host::io::lightfield::read_npy;

fn expected() -> serde_json::Value {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/metrics/expected.json"))
            .unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn metrics_match_scikit_image() {
    let exp = expected();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/metrics");
    for case in ["noise", "blur_shift"] {
        let truth = read_npy(&dir.join(format!("case_{case}_truth.npy"))).unwrap();
        let recon = read_npy(&dir.join(format!("case_{case}_recon.npy"))).unwrap();
        let m = evaluate(&truth, &recon).unwrap();
        let e = &exp[case];
        let close = |got: f64, key: &str| {
            let want = e[key].as_f64().unwrap();
            assert!((got - want).abs() <= 1e-4, "{case} {key}: {got} vs scikit-image {want}");
        };
        close(m.data_range, "data_range");
        close(m.psnr, "psnr");
        close(m.ssim, "ssim");
        close(m.sa, "sa");
    }
}

#[test]
fn identical_light_fields_are_perfect() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/metrics");
    let t = read_npy(&dir.join("case_noise_truth.npy")).unwrap();
    let m = evaluate(&t, &t).unwrap();
    assert!(m.psnr.is_infinite());
    assert!((m.ssim - 1.0).abs() < 1e-12);
    assert!(m.sa.abs() < 1e-3, "{}", m.sa);
    let mut other = t.clone();
    other.rows -= 1;
    assert!(evaluate(&t, &other).unwrap_err().to_string().contains("shapes differ"));
}

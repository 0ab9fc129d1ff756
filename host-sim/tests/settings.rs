//! The decode's settings as `slf decode`'s flags give them: the presets, a flag over a
//! preset, and one-line errors naming the flag (moved from `decode/settings.rs`'s unit tests).

use slf_firmware::{DisparityRange, Sl0Config};
use slf_host::decode::cs::{Balance, Basis, DecodeOptions, NoiseSource};
use slf_host::decode::preset::Preset;
use slf_host::decode::settings::DecodeSettings;
use slf_host::sim::flags::FromFlags;

fn resolved(flags: &[&str]) -> (Basis, DecodeOptions) {
    DecodeSettings::from_flags(flags).and_then(|s| s.resolve().map_err(|e| e.to_string())).unwrap()
}

#[test]
fn no_flags_is_the_default_preset() {
    let (basis, o) = resolved(&[]);
    let d = Preset::Default.options();
    assert_eq!(basis.name(), Preset::Default.basis().name());
    assert_eq!(
        (o.stride, o.window, o.disparities, o.edge_fallback, o.sheared_fallback),
        (d.stride, d.window, d.disparities, d.edge_fallback, d.sheared_fallback)
    );
    assert_eq!(o.sl0, Sl0Config::DEFAULT);
    assert_eq!((o.noise, o.balance), (NoiseSource::Capture, Balance::GreyWorld));
}

#[test]
fn a_preset_then_flags_over_it() {
    let p = Preset::Preview.options();
    let (basis, o) = resolved(&["--preset", "preview"]);
    assert!(matches!(basis, Basis::Dct));
    assert_eq!(
        (o.stride, o.window, o.disparities, o.edge_fallback, o.sheared_fallback),
        (p.stride, p.window, p.disparities, p.edge_fallback, p.sheared_fallback)
    );
    assert_eq!((o.sl0.sigma_min, o.sl0.cold_start), (p.sl0.sigma_min, p.sl0.cold_start));
    let (basis, o) = resolved(&[
        "--preset=preview",
        "--stride=2",
        "--dictionary=ensemble",
        "--sigma-min=0.002",
        "--disparities=-2:2:0.5",
    ]);
    assert!(matches!(basis, Basis::Ensemble { .. }));
    assert_eq!((o.stride, o.window, o.sl0.sigma_min, o.sl0.cold_start), ((2, 2), p.window, 0.002, p.sl0.cold_start));
    assert_eq!(o.disparities, DisparityRange::new(-2, 2).map(|r| r.with_halves(true)));
    let (_, o) = resolved(&["--exact", "--balance", "off", "--edge-fallback", "false", "--seeded", "false"]);
    assert_eq!((o.noise, o.balance, o.edge_fallback, o.seeded), (NoiseSource::Config, Balance::Off, false, false));
    assert!(resolved(&[]).1.seeded);
}

#[test]
fn errors_are_one_line_and_name_the_flag() {
    for (flags, says) in [
        (&["--stride", "9"][..], "--stride"),
        (&["--preset", "fast"][..], "--preset"),
        (&["--disparities", "3:1"][..], "MIN:MAX"),
        (&["--exact", "--noise", "0.1"][..], "--noise"),
        (&["--bogus"][..], "--bogus"),
    ] {
        let e = DecodeSettings::from_flags(flags).unwrap_err();
        assert!(e.contains(says) && !e.contains('\n') && !e.starts_with("error"), "{flags:?}: {e}");
    }
    let s = DecodeSettings::from_flags(["--gains", "1,2"]).unwrap();
    assert_eq!(s.resolve().unwrap_err().to_string(), "--gains: 13 values, got 2");
    // A solver value out of its range: the flag, the value and the range.
    let s = DecodeSettings::from_flags(["--sigma-f", "1.5"]).unwrap();
    assert_eq!(s.resolve().unwrap_err().to_string(), "--sigma-f 1.5: must be in (0, 1)");
    let s = DecodeSettings::from_flags(["--cold-start=0"]).unwrap();
    assert_eq!(s.resolve().unwrap_err().to_string(), "--cold-start 0: must be in (0, 1]");
    let s = DecodeSettings::from_flags(["--mu=-1"]).unwrap();
    assert!(s.resolve().unwrap_err().to_string().starts_with("--mu -1: must be in (0, 2]"));
    // Absurd values of every solver and noise flag (issue 32, item 4), each named with
    // its range; the range's ends are taken.
    for (flag, bad, good, range) in [
        ("--mu", ["5", "10", "100", "1e30"], "2", "in (0, 2]"),
        ("--sigma-min", ["1.5", "1e30", "0", "inf"], "1", "in (0, 1]"),
        ("--tolerance", ["1.5", "1e30", "-1", "NaN"], "1", "in [0, 1]"),
        ("--noise", ["1.5", "1e30", "-1", "inf"], "1", "in [0, 1]"),
        ("--shot", ["1.5", "1e30", "-1", "inf"], "1", "in [0, 1]"),
        ("--flat", ["1.5", "1e30", "-1", "inf"], "1", "in [0, 1]"),
        ("--seed-sigma-f", ["1", "0", "1e30", "NaN"], "0.5", "in (0, 1)"),
    ] {
        for v in bad {
            let arg = format!("{flag}={v}");
            let e = DecodeSettings::from_flags([arg.as_str()]).unwrap().resolve().unwrap_err().to_string();
            assert!(e.starts_with(&format!("{flag} ")) && e.contains(range) && !e.contains('\n'), "{arg}: {e}");
        }
        // (The hand-set schedule's flags are taken with it.)
        resolved(&[&format!("{flag}={good}"), "--schedule", "annealed"]);
    }
    let e = DecodeSettings::from_flags(["--tolerance=1"]).unwrap().resolve().unwrap_err().to_string();
    assert_eq!(e, "--tolerance sets the hand-set schedule, which the trained one replaces: add --schedule annealed");
    for g in ["1e30", "0", "0.01", "65", "nan"] {
        let arg = format!("--gains=1,1,1,{g},1,1,1,1,1,1,1,1,1");
        let e = DecodeSettings::from_flags([arg.as_str()]).unwrap().resolve().unwrap_err().to_string();
        assert!(e.starts_with("--gains: gain 4 is ") && e.contains("[1/64, 64]"), "{arg}: {e}");
    }
    resolved(&["--gains=64,0.015625,1,1,1,1,1,1,1,1,1,1,1"]);
    // Flags that would be ignored are refused (issue 32, items 5 and 9).
    for (flags, says) in [
        (&["--min-bands", "14"][..], "--min-bands 14: at most 13"),
        (&["--adaptive", "2", "--stride", "5"][..], "--adaptive needs a stride below 5"),
        (&["--adaptive", "2", "--preset", "preview"][..], "--adaptive needs a stride below 5"),
        (&["--seeded", "true", "--preset", "preview"][..], "--seeded true needs a stride below 5"),
        (
            &["--blob", "e.slfd", "--dictionary", "dct"][..],
            "--blob names an ensemble, but this decode uses the DCT (--dictionary dct)",
        ),
        (&["--blob", "e.slfd", "--preset", "preview"][..], "(--preset preview)"),
    ] {
        let e = DecodeSettings::from_flags(flags).unwrap().resolve().unwrap_err().to_string();
        assert!(e.contains(says), "{flags:?}: {e}");
    }
    resolved(&["--min-bands", "13"]);
    resolved(&["--adaptive", "2"]);
    let s = DecodeSettings::from_flags(["--adaptive=-1"]).unwrap();
    assert!(s.resolve().unwrap_err().to_string().starts_with("--adaptive -1"));
}

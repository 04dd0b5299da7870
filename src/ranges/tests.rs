//! The table's own checks.
use super::*;

#[test]
fn words_and_bounds() {
    assert_eq!(INSTRUMENT_APERTURE_MM.allowed(), "above 0, at most 2000 mm");
    assert_eq!(INSTRUMENT_ADC_BITS.allowed(), "1 to 16 bits (whole number)");
    assert_eq!(ACCURACY_ORDER_TOLERANCE.allowed(), "above 0, below 0.1");
    assert_eq!(CALIBRATION_SUN_INCIDENCE_DEG.allowed(), "0 to below 89 degrees");
    assert_eq!(
        INSTRUMENT_GAIN_E_PER_DN.check(0.001),
        Err("0.001 is out of range (allowed: 0.01 to 10000 e-/DN)".into())
    );
    assert!(INSTRUMENT_ADC_BITS.check(12.5).is_err() && INSTRUMENT_ADC_BITS.check(12.0).is_ok());
    assert!(!CALIBRATION_SUN_INCIDENCE_DEG.contains(89.0) && CALIBRATION_SUN_INCIDENCE_DEG.contains(88.9));
    assert_eq!(INSTRUMENT_APERTURE_MM.just_outside(), vec![0.0, 2020.0]);
    assert_eq!(INSTRUMENT_ADC_BITS.just_outside(), vec![0.0, 17.0]);
    assert_eq!(CALIBRATION_DIFFUSER_BIAS_PCT.just_outside(), vec![-50.5, 50.5]);
    assert_eq!(INSTRUMENT_APERTURE_MM.name(), "aperture_mm");
}

#[test]
fn every_range_is_well_formed_and_named_once() {
    let mut paths: Vec<&str> = ALL.iter().map(|r| r.path).collect();
    paths.sort_unstable();
    paths.dedup();
    assert_eq!(paths.len(), ALL.len(), "a path is listed twice");
    for r in ALL {
        assert!(r.lo < r.hi && r.lo.is_finite() && r.hi.is_finite(), "{}", r.path);
        for v in r.just_outside() {
            assert!(!r.contains(v), "{}: {v}", r.path);
        }
        assert!(!r.contains(f64::NAN) && !r.contains(f64::INFINITY), "{}", r.path);
    }
}

/// docs/MANUAL.md's table is `shoal ranges`'s output, so the documentation is the code's.
#[test]
fn manual_shows_the_table() {
    let manual = include_str!("../../docs/MANUAL.md");
    let table = markdown_table();
    assert!(manual.contains(&table), "docs/MANUAL.md's table differs from `shoal ranges`; paste this:\n{table}");
}

//! Setting a numeric field of a run configuration by its path (`instrument.aperture_mm`): the
//! configuration layer's [`crate::fields::with_numbers`] on a [`RunConfig`] — the path walks the
//! fields' names and list indices of its serde form, the field must already hold a number, and the
//! result is read back and validated like any configuration, so every field the files can set can
//! be swept.

use crate::engine::RunConfig;

/// `base` with each `(path, value)` set. Integer fields take integral values only.
///
/// # Errors
/// A path that names no number, or a value its field cannot hold (the message names the path).
pub fn apply(base: &RunConfig, settings: &[(&str, f64)]) -> Result<RunConfig, String> {
    crate::fields::with_numbers(base, settings)
}

/// The number at `path` of `config` (`None`: no such field, or not a number there — a field of
/// another instrument kind, a map).
#[must_use]
pub fn value(config: &RunConfig, path: &str) -> Option<f64> {
    crate::fields::number(config, path)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::instrument::InstrumentSpec;
    use crate::scene::SceneSpec;

    fn base() -> RunConfig {
        RunConfig::new(SceneSpec::preset("lake_hume_bloom").unwrap(), InstrumentSpec::preset("cubesat").unwrap())
    }

    #[test]
    fn sets_floats_and_whole_numbers() {
        let c = apply(&base(), &[("instrument.aperture_mm", 123.5), ("instrument.adc_bits", 10.0)]).unwrap();
        assert_eq!(c.instrument.aperture_mm, 123.5);
        assert_eq!(c.instrument.adc_bits, 10);
        let mut expected = base();
        expected.instrument.aperture_mm = 123.5;
        expected.instrument.adc_bits = 10;
        assert_eq!(c, expected, "nothing else changes");
    }

    #[test]
    fn names_what_is_wrong() {
        let e = apply(&base(), &[("instrument.aperture", 1.0)]).unwrap_err();
        assert!(e.contains("no field `aperture`") && e.contains("aperture_mm"), "{e}");
        let e = apply(&base(), &[("instrument.adc_bits", 10.5)]).unwrap_err();
        assert!(e.contains("whole number"), "{e}");
        let e = apply(&base(), &[("instrument.name", 1.0)]).unwrap_err();
        assert!(e.contains("not a number"), "{e}");
    }
}

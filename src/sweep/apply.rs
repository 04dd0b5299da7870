//! Setting a numeric field of a run configuration by its path (`instrument.aperture_mm`).
//!
//! The configuration goes through its serde form (JSON values): the path walks object keys and
//! array indices, the field must already hold a number, and the result is read back and
//! validated like any configuration — so every field the files can set can be swept.

use serde_json::Value;

use crate::engine::RunConfig;

/// `base` with each `(path, value)` set. Integer fields take integral values only.
pub fn apply(base: &RunConfig, settings: &[(&str, f64)]) -> Result<RunConfig, String> {
    let mut tree = serde_json::to_value(base).map_err(|e| format!("cannot represent the configuration: {e}"))?;
    for &(path, value) in settings {
        set(&mut tree, path, value)?;
    }
    let config: RunConfig = serde_json::from_value(tree).map_err(|e| format!("`{settings:?}`: {e}"))?;
    Ok(config)
}

/// The number at `path` of `config` (`None`: no such field, or not a number there — a field of
/// another instrument kind, a map).
#[must_use]
pub fn value(config: &RunConfig, path: &str) -> Option<f64> {
    let tree = serde_json::to_value(config).ok()?;
    let mut node = &tree;
    for key in path.split('.') {
        node = match node {
            Value::Object(map) => map.get(key)?,
            Value::Array(items) => items.get(key.parse::<usize>().ok()?)?,
            _ => return None,
        };
    }
    node.as_f64()
}

fn set(tree: &mut Value, path: &str, value: f64) -> Result<(), String> {
    let mut node = tree;
    for key in path.split('.') {
        node = match node {
            Value::Object(map) => {
                let known: Vec<String> = map.keys().cloned().collect();
                map.get_mut(key)
                    .ok_or_else(|| format!("`{path}`: no field `{key}` here (fields: {})", known.join(", ")))?
            }
            Value::Array(items) => {
                let n = items.len();
                let i: usize = key.parse().map_err(|_| format!("`{path}`: `{key}` must be an index 0..{n} here"))?;
                items.get_mut(i).ok_or_else(|| format!("`{path}`: index {i} out of 0..{n}"))?
            }
            other => return Err(format!("`{path}`: `{key}` is inside a value that has no fields ({other})")),
        };
    }
    let Value::Number(n) = node else {
        return Err(format!("`{path}` is not a number (it holds {node})"));
    };
    *node = if n.is_f64() {
        serde_json::Number::from_f64(value)
            .map(Value::Number)
            .ok_or_else(|| format!("`{path}`: {value} is not finite"))?
    } else {
        if value.fract() != 0.0 || !(0.0..=9.0e15).contains(&value) {
            return Err(format!("`{path}` is a whole number; {value} is not (use a list of whole values)"));
        }
        Value::from(value as u64)
    };
    Ok(())
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

//! The instrument parameters the editor offers, read from the one parameter registry
//! ([`crate::ranges::INSTRUMENT_EDITOR`]: label, unit, scale, slider span, tip, and the range a
//! typed value must meet), and how each reads and writes an instrument — through the
//! instrument's serde form, as sweeps set any field by its path (`crate::sweep::apply`).

use crate::instrument::InstrumentSpec;
use crate::ranges::{Editor, INSTRUMENT_EDITOR, Range};

/// One numeric instrument parameter as the editor shows it.
pub struct Param {
    /// The `InstrumentSpec` field (`aperture_mm`).
    pub key: &'static str,
    /// Its range (what a typed value must meet).
    pub range: &'static Range,
    /// How the editor shows it.
    pub editor: &'static Editor,
}

impl Param {
    /// The slider's label.
    #[must_use]
    pub fn label(&self) -> &'static str {
        self.editor.label
    }

    /// The unit as a slider suffix (" mm"; empty: none).
    #[must_use]
    pub fn suffix(&self) -> String {
        if self.editor.unit.is_empty() { String::new() } else { format!(" {}", self.editor.unit) }
    }
}

/// The parameters, in the editor's order.
pub fn params() -> impl Iterator<Item = Param> {
    INSTRUMENT_EDITOR
        .iter()
        .filter_map(|range| range.editor.as_ref().map(|editor| Param { key: range.name(), range, editor }))
}

/// The editor's parameter called `key`.
#[must_use]
pub fn param(key: &str) -> Option<Param> {
    params().find(|p| p.key == key)
}

/// Every editor parameter's stored value of `spec`, in [`params`] order (one pass over its serde
/// form; NaN for a field it does not hold).
#[must_use]
pub fn values(spec: &InstrumentSpec) -> Vec<f64> {
    crate::fields::numbers(spec, params().map(|p| p.key))
}

/// `spec` with field `key` set to `value` (stored units), or why not (not a field, a whole number
/// given a fraction). Not validated: the caller checks the instrument.
pub fn with_value(spec: &InstrumentSpec, key: &str, value: f64) -> Result<InstrumentSpec, String> {
    crate::fields::with_numbers(spec, &[(key, value)])
}

/// The parameters in which the designs differ from the first (the reference), as rows
/// (parameter, a value per design) with a header row of the designs' names, in the editor's
/// names and units; each design given as (name, instrument, band count). One row saying so when
/// none differs. Shown in the app ("Parameters against A") and on the review slide.
#[must_use]
pub fn differences(designs: &[(&str, &InstrumentSpec, usize)]) -> Vec<Vec<String>> {
    let mut header = vec!["parameter".to_string()];
    header.extend(designs.iter().map(|d| d.0.to_string()));
    let mut rows = vec![header];
    let show = |v: f64| {
        let m = v.abs();
        if m == 0.0 || (0.01..1e7).contains(&m) { format!("{}", (v * 1e4).round() / 1e4) } else { format!("{v:.3e}") }
    };
    let Some((_, _, reference_bands)) = designs.first() else { return rows };
    let stored: Vec<Vec<f64>> = designs.iter().map(|d| values(d.1)).collect();
    for (k, p) in params().enumerate() {
        let shown: Vec<f64> = stored.iter().map(|v| v[k] * p.editor.scale).collect();
        let x = shown[0];
        if shown.iter().any(|y| (x - y).abs() > 1e-12 * x.abs().max(y.abs())) {
            let mut row = vec![p.label().to_string()];
            row.extend(shown.iter().map(|v| format!("{}{}", show(*v), p.suffix())));
            rows.push(row);
        }
    }
    if designs.iter().any(|d| d.2 != *reference_bands) {
        let mut row = vec!["bands".to_string()];
        row.extend(designs.iter().map(|d| d.2.to_string()));
        rows.push(row);
    }
    if rows.len() == 1 {
        let mut row = vec!["(none: the designs are the same instrument)".to_string()];
        row.extend(designs.iter().map(|_| String::new()));
        rows.push(row);
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_editor_reads_and_writes_every_parameter_through_the_registry() {
        let spec = InstrumentSpec::preset("cubesat").unwrap();
        let v = values(&spec);
        assert_eq!(v.len(), 13);
        assert_eq!((v[0], v[5]), (60.0, 0.0015), "aperture, exposure (stored in s)");
        for (k, p) in params().enumerate() {
            let moved = if p.range.whole { v[k] + 1.0 } else { v[k] * 1.1 + 0.01 };
            let edited = with_value(&spec, p.key, moved).unwrap();
            assert_eq!(values(&edited)[k], moved, "{}", p.key);
            assert!(p.range.path.ends_with(p.key) && !p.label().is_empty());
        }
        assert!(with_value(&spec, "adc_bits", 12.5).unwrap_err().contains("whole number"));
        assert!(with_value(&spec, "no_such_field", 1.0).is_err());
    }

    #[test]
    fn differences_list_what_differs_in_the_editors_units() {
        let a = InstrumentSpec::preset("cubesat").unwrap();
        let b = InstrumentSpec::preset("smallsat").unwrap();
        let rows = differences(&[("A", &a, 8), ("B", &b, 8)]);
        assert_eq!(rows[0], ["parameter", "A", "B"]);
        assert!(rows.contains(&vec!["Aperture".into(), "60 mm".into(), "240 mm".into()]), "{rows:?}");
        assert!(rows.iter().all(|r| r[0] != "Lines"), "equal parameters are not listed");
        assert_eq!(differences(&[("A", &a, 8), ("B", &a, 8)])[1][0], "(none: the designs are the same instrument)");
        // A third design that differs only in bands from the reference adds that row alone.
        let rows = differences(&[("A", &a, 8), ("B", &a, 8), ("C", &a, 19)]);
        assert_eq!(rows, [vec!["parameter", "A", "B", "C"], vec!["bands", "8", "8", "19"]]);
    }
}

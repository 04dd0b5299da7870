//! The instrument parameters the editor offers: label, unit, slider span, scale and tip, and how
//! each reads and writes the instrument.

use crate::instrument::InstrumentSpec;

/// One numeric instrument parameter as the editor shows it.
pub struct Param {
    /// The `InstrumentSpec` field (and `src/ranges.rs` path below `instrument.`).
    pub key: &'static str,
    /// The slider's label.
    pub label: &'static str,
    /// Unit suffix as shown.
    pub unit: &'static str,
    /// The slider's span (a typed value may leave it; the documented range decides).
    pub range: (f64, f64),
    /// Logarithmic slider.
    pub log: bool,
    /// Display = stored × scale (exposure in ms).
    pub scale: f64,
    /// Hover text.
    pub tip: &'static str,
    /// Read it from an instrument.
    pub get: fn(&InstrumentSpec) -> f64,
    /// Write it into an instrument.
    pub set: fn(&mut InstrumentSpec, f64),
}

/// The parameters, in the editor's order.
pub const PARAMS: [Param; 13] = [
    Param {
        key: "aperture_mm",
        label: "Aperture",
        unit: " mm",
        range: (10.0, 500.0),
        log: true,
        scale: 1.0,
        tip: "Entrance pupil diameter: photons grow with its square",
        get: |s| s.aperture_mm,
        set: |s, v| s.aperture_mm = v,
    },
    Param {
        key: "pixel_pitch_um",
        label: "Pixel pitch",
        unit: " µm",
        range: (1.0, 30.0),
        log: false,
        scale: 1.0,
        tip: "Detector pixel size: sets GSD with altitude and focal length",
        get: |s| s.pixel_pitch_um,
        set: |s, v| s.pixel_pitch_um = v,
    },
    Param {
        key: "focal_length_mm",
        label: "Focal length",
        unit: " mm",
        range: (20.0, 2000.0),
        log: true,
        scale: 1.0,
        tip: "GSD = altitude × pitch / focal length",
        get: |s| s.focal_length_mm,
        set: |s, v| s.focal_length_mm = v,
    },
    Param {
        key: "detectors",
        label: "Detectors",
        unit: "",
        range: (16.0, 4096.0),
        log: true,
        scale: 1.0,
        tip: "Detectors across track (swath = detectors × GSD)",
        get: |s| s.detectors as f64,
        set: |s, v| s.detectors = v.round() as usize,
    },
    Param {
        key: "lines",
        label: "Lines",
        unit: "",
        range: (16.0, 4000.0),
        log: true,
        scale: 1.0,
        tip: "Exposures along track",
        get: |s| s.lines as f64,
        set: |s, v| s.lines = v.round() as usize,
    },
    Param {
        key: "exposure_s",
        label: "Exposure",
        unit: " ms",
        range: (0.1, 20.0),
        log: true,
        scale: 1000.0,
        tip: "Integration time per line",
        get: |s| s.exposure_s,
        set: |s, v| s.exposure_s = v,
    },
    Param {
        key: "well_depth_e",
        label: "Well depth",
        unit: " e⁻",
        range: (1000.0, 2_000_000.0),
        log: true,
        scale: 1.0,
        tip: "Full-well capacity: saturation above it",
        get: |s| s.well_depth_e,
        set: |s, v| s.well_depth_e = v,
    },
    Param {
        key: "gain_e_per_dn",
        label: "Gain",
        unit: " e⁻/DN",
        range: (0.1, 100.0),
        log: true,
        scale: 1.0,
        tip: "Conversion gain: quantisation noise gain²/12",
        get: |s| s.gain_e_per_dn,
        set: |s, v| s.gain_e_per_dn = v,
    },
    Param {
        key: "read_noise_e",
        label: "Read noise",
        unit: " e⁻",
        range: (0.0, 100.0),
        log: false,
        scale: 1.0,
        tip: "Readout noise, electrons rms",
        get: |s| s.read_noise_e,
        set: |s, v| s.read_noise_e = v,
    },
    Param {
        key: "bias_dn",
        label: "Bias",
        unit: " DN",
        range: (0.0, 1000.0),
        log: false,
        scale: 1.0,
        tip: "ADC offset",
        get: |s| s.bias_dn,
        set: |s, v| s.bias_dn = v,
    },
    Param {
        key: "adc_bits",
        label: "ADC bits",
        unit: "",
        range: (4.0, 16.0),
        log: false,
        scale: 1.0,
        tip: "Converter resolution: 2^bits − 1 is the largest count",
        get: |s| f64::from(s.adc_bits),
        set: |s, v| s.adc_bits = v.round() as u32,
    },
    Param {
        key: "optical_transmission",
        label: "Optical transmission",
        unit: "",
        range: (0.1, 1.0),
        log: false,
        scale: 1.0,
        tip: "Throughput of the optics and filters",
        get: |s| s.optical_transmission,
        set: |s, v| s.optical_transmission = v,
    },
    Param {
        key: "altitude_km",
        label: "Altitude",
        unit: " km",
        range: (200.0, 1500.0),
        log: false,
        scale: 1.0,
        tip: "Orbit altitude: GSD and ground speed",
        get: |s| s.altitude_km,
        set: |s, v| s.altitude_km = v,
    },
];

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
    let Some((_, reference, reference_bands)) = designs.first() else { return rows };
    for p in &PARAMS {
        let x = (p.get)(reference) * p.scale;
        let values: Vec<f64> = designs.iter().map(|d| (p.get)(d.1) * p.scale).collect();
        if values.iter().any(|y| (x - y).abs() > 1e-12 * x.abs().max(y.abs())) {
            let mut row = vec![p.label.to_string()];
            row.extend(values.iter().map(|v| format!("{}{}", show(*v), p.unit)));
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

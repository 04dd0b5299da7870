use super::*;

/// The cubesat preset's first plane at nadir.
fn cubesat() -> MtfGeometry {
    let spec = crate::instrument::InstrumentSpec::preset("cubesat").unwrap();
    crate::instrument::spatial::first_plane_geometry(&spec)
}

#[test]
fn an_unobstructed_pupil_is_the_circular_otf_and_obstruction_moves_contrast_up() {
    // ε = 0: (2/π)(acos v − v√(1 − v²)); 0.5 → 0.3910 (Goodman 2005, eq. 6-32).
    assert!((annular_otf(0.5, 0.0) - 0.391_002).abs() < 1e-6);
    assert!((annular_otf(0.0, 0.4) - 1.0).abs() < 1e-12);
    assert_eq!(annular_otf(1.0, 0.4), 0.0);
    // A central obstruction lowers mid frequencies and raises high ones (O'Neill 1956, Fig. 2).
    assert!(annular_otf(0.3, 0.5) < annular_otf(0.3, 0.0));
    assert!(annular_otf(0.85, 0.5) > annular_otf(0.85, 0.0));
}

#[test]
fn the_annular_formula_matches_the_pupils_own_autocorrelation() {
    // The OTF is the pupil's normalised autocorrelation (Goodman 2005, eq. 6-28): count the
    // overlap of an annulus of ε = 0.35 with itself shifted by 2v radii on a 801² grid. The
    // grid's edge pixels set the tolerance: 0.005.
    let eps = 0.35;
    let n = 801;
    let radius = 200.0;
    let inside = |x: f64, y: f64| {
        let r = x.hypot(y) / radius;
        r <= 1.0 && r >= eps
    };
    let pts: Vec<(f64, f64)> =
        (0..n * n).map(|i| ((i % n) as f64 - 400.0, (i / n) as f64 - 400.0)).filter(|&(x, y)| inside(x, y)).collect();
    let area = pts.len() as f64;
    for v in [0.1, 0.2, 0.3, 0.45, 0.6, 0.75, 0.9] {
        let shift = 2.0 * v * radius;
        let overlap = pts.iter().filter(|&&(x, y)| inside(x + shift, y)).count() as f64;
        let numeric = overlap / area;
        assert!((annular_otf(v, eps) - numeric).abs() < 5e-3, "v {v}: {} vs {numeric}", annular_otf(v, eps));
    }
}

#[test]
fn the_system_mtf_is_the_product_of_its_parts() {
    let g = cubesat();
    let b = MtfBudget {
        obstruction: 0.3,
        wavefront_rms_nm: 40.0,
        diffusion_um: 3.0,
        crosstalk: 0.05,
        jitter_urad: 5.0,
        ..MtfBudget::default()
    };
    let nu = g.nyquist_per_m();
    let parts = b.parts(&g, 550.0, nu, Axis::Along);
    let product: f64 = parts.iter().map(|p| p.1).product();
    assert!((b.otf(&g, 550.0, nu, Axis::Along) - product).abs() < 1e-15);
    // At Nyquist a full-fill pixel passes sinc(½) = 2/π, crosstalk 1 − 4c.
    let part = |name: &str| parts.iter().find(|p| p.0 == name).unwrap().1;
    assert!((part("pixel aperture") - 2.0 / PI).abs() < 1e-12);
    assert!((part("crosstalk") - (1.0 - 4.0 * 0.05)).abs() < 1e-12);
    // Across track there is no smear; along track the smear costs contrast.
    assert!(b.at_nyquist(&g, 550.0, Axis::Across) > b.at_nyquist(&g, 550.0, Axis::Along));
    // Every added part lowers the MTF at Nyquist.
    let ideal = MtfBudget::default();
    assert!(b.at_nyquist(&g, 550.0, Axis::Across) < ideal.at_nyquist(&g, 550.0, Axis::Across));
}

#[test]
fn the_line_spread_cells_transform_back_to_the_budget() {
    // Σ w_k cos(2πν x_k) over cells of width h is OTF(ν)·sinc(νh) (the cells' box) up to the
    // aliases at 1/h ± ν, which hold < 1e-3 here; the Simpson sum resolves every period with 16
    // points. The window spans 12 reaches, yet a circular pupil's line-spread function falls only
    // as 1/x² (its OTF has a kink at 0), so ~1e-3 of it lies beyond: 1.5e-3 on the total, 2e-3 on
    // the transform.
    let g = cubesat();
    let b = MtfBudget { obstruction: 0.25, wavefront_rms_nm: 30.0, jitter_urad: 3.0, ..MtfBudget::default() };
    let h = g.pitch_ground_m / 8.0;
    for axis in [Axis::Along, Axis::Across] {
        let k_max = (12.0 * b.reach_m(&g, 443.0, axis) / h).ceil() as usize;
        let w = b.cell_weights(&g, 443.0, axis, h, k_max);
        let total: f64 = w.iter().sum();
        assert!((total - 1.0).abs() < 1.5e-3, "{axis:?} total {total}");
        for nu in [0.25 * g.nyquist_per_m(), g.nyquist_per_m(), 1.5 * g.nyquist_per_m()] {
            let measured: f64 = w
                .iter()
                .enumerate()
                .map(|(k, wk)| wk * (2.0 * PI * nu * (k as f64 - k_max as f64) * h).cos())
                .sum::<f64>()
                / total;
            let expected = b.otf(&g, 443.0, nu, axis) * sinc(nu * h);
            assert!((measured - expected).abs() < 2e-3, "{axis:?} ν {nu}: {measured} vs {expected}");
        }
    }
}

#[test]
fn fields_out_of_range_are_named() {
    let b = MtfBudget { crosstalk: 0.3, ..MtfBudget::default() };
    let e = b.validate("instrument.effects[0].SpatialResponse").unwrap_err().to_string();
    assert!(e.contains("instrument.effects[0].SpatialResponse.crosstalk") && e.contains("0.2"), "{e}");
}

#[test]
fn tdi_costs_contrast_along_track_only() {
    // 16 stages, the line rate 1 % off, a CTE of 0.9999: at Nyquist the slip passes
    // sinc(16·0.01/2) and the transfers exp(−2·16·1e-4) (cos π = −1).
    let mut spec = crate::instrument::InstrumentSpec::preset("cubesat").unwrap();
    let tdi = crate::instrument::effects::Tdi { stages: 16, digital: false, line_rate_error: -0.01, cte: 0.9999 };
    spec.effects = vec![crate::instrument::InstrumentEffect::Tdi(tdi)];
    let g = crate::instrument::spatial::first_plane_geometry(&spec);
    let b = MtfBudget::default();
    let parts = b.parts(&g, 550.0, g.nyquist_per_m(), Axis::Along);
    let part = |name: &str| parts.iter().find(|p| p.0 == name).unwrap().1;
    let x = PI * 0.08;
    assert!((part("TDI line rate") - x.sin() / x).abs() < 1e-12);
    assert!((part("TDI transfer") - (-2.0 * 16.0 * 1e-4f64).exp()).abs() < 1e-12);
    let across = b.parts(&g, 550.0, g.nyquist_per_m(), Axis::Across);
    assert!(across[7].1 == 1.0 && across[8].1 == 1.0, "{across:?}");
    // Digital TDI moves no charge: no transfer loss.
    spec.effects =
        vec![crate::instrument::InstrumentEffect::Tdi(crate::instrument::effects::Tdi { digital: true, ..tdi })];
    assert_eq!(crate::instrument::spatial::first_plane_geometry(&spec).tdi_transfer_loss, 0.0);
}

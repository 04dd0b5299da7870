//! A spectral knowledge error through the chain (`instrument::effects::spectral_knowledge`):
//! the scene sampled through the bands the instrument has, the processor working with those it
//! believes.

use crate::common::Kept;

use shoal::calibration::band_e0;
use shoal::engine::{Fidelity, RunConfig, RunOutput};
use shoal::instrument::{DetectorMode, Response};

use super::{on_one_and_two_threads, run, small, small_lake};

/// A noise-free CubeSat over a cut of Lake Hume with `effects` (RON), calibrated from its
/// diffuser frames (the analogue values: no quantisation).
fn config(effects: &str) -> RunConfig {
    let mut instrument = small("cubesat", 96, 64);
    instrument.effects = ron::from_str(effects).unwrap();
    let mut c = RunConfig::new(small_lake(), instrument);
    c.detector = DetectorMode::IDEAL;
    c
}

/// Each band's Level-1 over the pupil radiance, minus 1, averaged over the values brighter than
/// 1e-6 (the pupil radiance is the true bands').
fn ratios(out: &RunOutput) -> Vec<f64> {
    let (l1, pupil) = (&out.kept().level1.radiance, &out.kept().radiance.radiance);
    let nb = l1.dim().2;
    (0..nb)
        .map(|b| {
            let (l, p) = (l1.index_axis(ndarray::Axis(2), b), pupil.index_axis(ndarray::Axis(2), b));
            let v: Vec<f64> =
                l.iter().zip(p).filter(|(_, t)| **t > 1e-6).map(|(l, t)| f64::from(*l) / f64::from(*t) - 1.0).collect();
            v.iter().sum::<f64>() / v.len() as f64
        })
        .collect()
}

/// The solar irradiance through the believed bands over that through the true ones, minus 1,
/// per band at the swath centre: what the diffuser calibration leaves on Level-1.
fn e0_ratios(c: &RunConfig) -> Vec<f64> {
    let step = c.fidelity.spectral_step_nm;
    let (believed, sensed) =
        (Response::new(&c.instrument, step).unwrap(), Response::sensed(&c.instrument, step).unwrap());
    let atmosphere = c.scene.atmosphere.build().unwrap();
    let e0: Vec<Vec<f64>> = believed
        .groups
        .iter()
        .map(|g| g.grid.wavelengths_nm().iter().map(|&w| atmosphere.e0(w).unwrap()).collect())
        .collect();
    let n = c.instrument.detectors;
    let (b, s) = (band_e0(&believed, n, &e0), band_e0(&sensed, n, &e0));
    let nb = believed.n_bands();
    let centre = n / 2;
    (0..nb).map(|k| b[centre * nb + k] / s[centre * nb + k] - 1.0).collect()
}

#[test]
fn an_exact_knowledge_changes_nothing() {
    let none = run(&config("[]"));
    let exact = run(&config("[SpectralKnowledge((centre_nm: 0.0, width_pct: 0.0))]"));
    assert_eq!(exact.kept().level1.radiance, none.kept().level1.radiance);
    assert_eq!(exact.kept().radiance.truth_rrs, none.kept().radiance.truth_rrs);
}

#[test]
fn a_band_shift_leaves_the_solar_ratio_on_level1() {
    // Every band 1.5 nm redder and 10 % wider than the processor believes.
    let c = config("[SpectralKnowledge((centre_nm: 1.5, width_pct: 10.0))]");
    let out = run(&c);
    let expected = e0_ratios(&c);
    let base = ratios(&run(&config("[]")));
    let got = ratios(&out);
    eprintln!("spectral knowledge: Level-1/pupil − 1 per band {got:?}, solar ratio {expected:?}");
    // The calibration's gain divides by the believed diffuser radiance, so Level-1 is the true
    // band's radiance times E0(believed)/E0(true). The test's ratio is at the swath centre;
    // the CubeSat has no smile, so every detector's is the same. Tolerance: the noise-free
    // chain's own closure (base, ~1e-6) plus the f32 rounding.
    for ((g, e), b) in got.iter().zip(&expected).zip(&base) {
        assert!((g - b - e).abs() < 5e-6, "{g} against {e} (base {b})");
    }
    // A 1.5 nm shift of a 10–20 nm band through the solar spectrum's structure: per-mille to
    // per-cent, not nothing.
    let largest = expected.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!((1e-3..5e-2).contains(&largest), "{expected:?}");
}

#[test]
fn the_truth_stays_in_the_stated_bands_and_the_pupil_moves() {
    // The full spectral grid (no band nodes): the truth's weights are the stated bands' exactly.
    let full = |effects: &str| {
        let mut c = config(effects);
        c.fidelity = Fidelity::full();
        run(&c)
    };
    let none = full("[]");
    let shifted = full("[SpectralKnowledge((sigma_nm: 1.0, draw: 3))]");
    assert_eq!(shifted.kept().radiance.truth_rrs, none.kept().radiance.truth_rrs);
    assert_ne!(shifted.kept().radiance.radiance, none.kept().radiance.radiance);
}

#[test]
fn a_spectral_error_grows_the_product_error_and_does_not_depend_on_threads() {
    let chl = |out: &RunOutput| out.retrievals[0].metrics.get("chl_mg_m3").unwrap().mae;
    let almi = |effects: &str| {
        let mut c = config(effects);
        c.retrievals = vec![ron::from_str("Almi()").unwrap()];
        c
    };
    let none = run(&almi("[]"));
    let c = almi("[SpectralKnowledge((centre_nm: 2.0))]");
    let (one, two) = on_one_and_two_threads(&c);
    assert_eq!(one.kept().level1.radiance, two.kept().level1.radiance);
    eprintln!("chl MAE (10^mean|Δlog|): bands as believed {:.4}, 2 nm redder {:.4}", chl(&none), chl(&one));
    assert!(chl(&one) > chl(&none), "{} against {}", chl(&one), chl(&none));
}

#[test]
fn per_band_shifts_of_the_wrong_length_are_refused_by_name() {
    let c = config("[SpectralKnowledge((per_band_nm: [0.5, 0.5]))]");
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("per_band_nm") && e.contains("2 shifts for"), "{e}");
    let c = config("[SpectralKnowledge((centre_nm: 20.0))]");
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("SpectralKnowledge.centre_nm") && e.contains("10"), "{e}");
}

#[test]
fn over_an_aerosol_map_the_true_bands_get_their_own_nodes_and_share_the_aot_range() {
    use shoal::engine::{Engine, Stage};
    let mut c = config("[SpectralKnowledge((centre_nm: 1.5))]");
    c.scene.aot550_map = Some(shoal::scene::MapSpec::Gradient { from: 0.05, to: 0.35, angle_deg: 0.0 });
    let mut engine = Engine::new();
    let out = engine.run(&c, &shoal::control::RunControl::new()).unwrap();
    // The band-atmosphere stage: the stated bands' terms, the AOT range under the pixels, the
    // stated bands' AOT nodes, the true bands' terms and their AOT nodes; the range once.
    assert_eq!(engine.executions(Stage::BandAtmosphere), 5);
    // The calibration's relation holds under the haze front as under one AOT.
    let (got, expected) = (ratios(&out), e0_ratios(&c));
    let base = ratios(&run(&{
        let mut none = config("[]");
        none.scene.aot550_map = c.scene.aot550_map.clone();
        none
    }));
    for ((g, e), b) in got.iter().zip(&expected).zip(&base) {
        assert!((g - b - e).abs() < 5e-6, "{g} against {e} (base {b})");
    }
}

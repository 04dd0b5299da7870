//! `shoal bench --accuracy`: the cost of accuracy. Every fidelity setting trades time for error;
//! this runs the CubeSat over Lake Hume once per setting (a fresh engine each, so nothing comes
//! from the cache) and compares the products with the full-fidelity run of the same
//! configuration and seed:
//!
//! - **ΔMAE**: the chl-a log-space MAE against the truth, minus the reference's (points of %);
//! - **chl per pixel**: median |retrieved / reference retrieved − 1| over pixels both return
//!   (same grid only; a coarser grid has other pixels);
//! - **Rrs(443) per pixel**: median |Rrs / reference Rrs − 1| over water pixels (same grid only).

use std::fmt::Write as _;
use std::time::Instant;

use super::CliError;
use crate::control::RunControl;
use crate::engine::{Engine, RunConfig, RunOutput};
use crate::instrument::InstrumentSpec;
use crate::scene::SceneSpec;
use crate::sweep::apply;

/// One fidelity setting: its label and the fields it sets.
struct Setting {
    label: String,
    set: Vec<(&'static str, f64)>,
}

fn settings(base_decimation: usize) -> Vec<Setting> {
    let s = |label: &str, set: Vec<(&'static str, f64)>| Setting { label: label.into(), set };
    let mut out = vec![s("reference (defaults)", vec![])];
    for d in [2, 4, 8, 16, 24] {
        out.push(s(
            &format!("preview 1/{}", d * base_decimation),
            vec![("fidelity.decimation", (d * base_decimation) as f64)],
        ));
    }
    out.extend([
        s("spectral step 2 nm", vec![("fidelity.spectral_step_nm", 2.0)]),
        s("spectral step 5 nm", vec![("fidelity.spectral_step_nm", 5.0)]),
        s("LUT wavelength nodes 10 nm", vec![("fidelity.lut_wavelength_step_nm", 10.0)]),
        s("LUT wavelength nodes 40 nm", vec![("fidelity.lut_wavelength_step_nm", 40.0)]),
        s("LUT view nodes 10°", vec![("fidelity.lut_view_step_deg", 10.0)]),
        s("RT 8 streams", vec![("scene.atmosphere.accuracy.streams", 8.0)]),
        s("RT 16 streams", vec![("scene.atmosphere.accuracy.streams", 16.0)]),
        s("RT single scattering", vec![("scene.atmosphere.accuracy.max_orders", 1.0)]),
        s("RT 8 Fourier terms", vec![("scene.atmosphere.accuracy.fourier_terms", 8.0)]),
        s("SNR patch 16 frames", vec![("fidelity.snr_frames", 16.0)]),
        s(
            "fast: 2 nm, LUT 40 nm, 8 streams",
            vec![
                ("fidelity.spectral_step_nm", 2.0),
                ("fidelity.lut_wavelength_step_nm", 40.0),
                ("scene.atmosphere.accuracy.streams", 8.0),
            ],
        ),
    ]);
    out
}

fn chl_mae(out: &RunOutput) -> f64 {
    out.retrievals.first().and_then(|r| r.metrics.get("chl_mg_m3")).map_or(f64::NAN, crate::metrics::Metrics::mae_pct)
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// Median relative difference of retrieved chl and of Rrs at the band nearest 443 nm, when the
/// grids match.
fn per_pixel(out: &RunOutput, reference: &RunOutput) -> (Option<f64>, Option<f64>) {
    let (Some(a), Some(b)) = (out.retrievals.first(), reference.retrievals.first()) else { return (None, None) };
    if a.product.chl_mg_m3.dim() != b.product.chl_mg_m3.dim()
        || out.correction.rrs.rrs.dim() != reference.correction.rrs.rrs.dim()
    {
        return (None, None);
    }
    let (rows, cols) = a.product.chl_mg_m3.dim();
    let mut chl = Vec::new();
    let mut rrs = Vec::new();
    let band = out
        .response
        .bands
        .bands
        .iter()
        .enumerate()
        .min_by(|x, y| (x.1.centre_nm - 443.0).abs().total_cmp(&(y.1.centre_nm - 443.0).abs()))
        .map_or(0, |(i, _)| i);
    for r in 0..rows {
        for c in 0..cols {
            if a.product.returned(r, c) && b.product.returned(r, c) {
                let (x, y) = (f64::from(a.product.chl_mg_m3[[r, c]]), f64::from(b.product.chl_mg_m3[[r, c]]));
                if y > 0.0 {
                    chl.push((x / y - 1.0).abs());
                }
            }
            if out.radiance.land[[r, c]] == 0 {
                let (x, y) = (
                    f64::from(out.correction.rrs.rrs[[r, c, band]]),
                    f64::from(reference.correction.rrs.rrs[[r, c, band]]),
                );
                if y.abs() > 1e-6 {
                    rrs.push((x / y - 1.0).abs());
                }
            }
        }
    }
    (median(chl), median(rrs))
}

/// The cost-of-accuracy table (Markdown).
pub fn accuracy_rows(out: &mut String, quick: bool) -> Result<(), CliError> {
    let base_decimation = if quick { 4 } else { 1 };
    let mut base = RunConfig::new(SceneSpec::preset("lake_hume_bloom")?, InstrumentSpec::preset("cubesat")?);
    base.retrievals = vec![crate::retrieval::RetrievalSpec::Almi {
        siop_sets: crate::retrieval::sets::default_almi_sets(),
        settings: Default::default(),
    }];
    base.fidelity.decimation = base_decimation;
    let control = RunControl::new();
    let _ = writeln!(out, "\n## Cost of accuracy (CubeSat over Lake Hume, aLMI, seed 1; a fresh engine per row)\n");
    let _ = writeln!(
        out,
        "| setting | time s | × reference | chl MAE % | ΔMAE vs reference (points) | chl per pixel vs reference, median % | Rrs(443) per pixel, median % |\n|---|---|---|---|---|---|---|"
    );
    let mut reference: Option<(RunOutput, f64)> = None;
    for setting in settings(base_decimation) {
        let config = apply(&base, &setting.set).map_err(CliError::Input)?;
        let mut engine = Engine::new();
        let start = Instant::now();
        let run = engine.run(&config, &control).map_err(|e| CliError::Run(e.to_string()))?;
        let secs = start.elapsed().as_secs_f64();
        let mae = chl_mae(&run);
        let (ratio, dmae, chl, rrs) = match &reference {
            None => (1.0, 0.0, Some(0.0), Some(0.0)),
            Some((r, t)) => {
                let (chl, rrs) = per_pixel(&run, r);
                (secs / t, mae - chl_mae(r), chl, rrs)
            }
        };
        let pct = |v: Option<f64>| v.map_or_else(|| "– (other grid)".to_string(), |v| format!("{:.3}", 100.0 * v));
        let _ = writeln!(
            out,
            "| {} | {secs:.2} | {ratio:.2} | {mae:.1} | {dmae:+.2} | {} | {} |",
            setting.label,
            pct(chl),
            pct(rrs)
        );
        super::output::emit(&std::mem::take(out), None)?;
        if reference.is_none() {
            reference = Some((run, secs));
        }
    }
    let _ = writeln!(
        out,
        "\nEach row changes one setting from the defaults (the last, three). Per-pixel columns compare the same pixels with the same noise, so they isolate the setting's own error; a preview's ΔMAE mixes that with fewer pixels in the sample."
    );
    Ok(())
}

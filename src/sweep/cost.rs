//! The cost of accuracy: every fidelity setting trades time for error. [`cost_of_accuracy`] runs
//! a configuration once per setting (a fresh engine each, so nothing comes from the cache) and
//! compares the products with the full-fidelity run of the same configuration and seed:
//!
//! - **ΔMAE**: the chl-a log-space MAE against the truth, minus the reference's (points of %);
//! - **chl per pixel**: median |retrieved / reference retrieved − 1| over pixels both return
//!   (same grid only; a coarser grid has other pixels);
//! - **Rrs(443) per pixel**: median |Rrs / reference Rrs − 1| over water pixels (same grid only).

use std::time::Instant;

use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RunConfig, RunOutput};
use crate::parse::FieldError;
use crate::study::StudyError;

use super::apply;

/// One measured setting.
#[derive(Debug, Clone, PartialEq)]
pub struct CostRow {
    /// What the setting is.
    pub label: String,
    /// Wall time of the whole chain, s.
    pub seconds: f64,
    /// Time over the reference's.
    pub ratio: f64,
    /// chl-a MAE against the truth, %.
    pub chl_mae_pct: f64,
    /// `chl_mae_pct` minus the reference's, points of %.
    pub delta_mae_pct: f64,
    /// Median per-pixel chl difference from the reference, % (same grid only).
    pub chl_pixel_pct: Option<f64>,
    /// Median per-pixel Rrs(443) difference from the reference, % (same grid only).
    pub rrs_pixel_pct: Option<f64>,
}

/// One fidelity setting: its label and the fields it sets.
pub struct Setting {
    /// Label.
    pub label: String,
    /// Fields set.
    pub set: Vec<(&'static str, f64)>,
}

/// The settings measured: the reference, previews at 2–24× the base decimation, spectral
/// step, LUT nodes, radiative-transfer streams, orders and Fourier terms, the SNR patch, and one
/// combination.
#[must_use]
pub fn settings(base_decimation: usize) -> Vec<Setting> {
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
            if out.radiance.truth.land[[r, c]] == 0 {
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

/// Measure every setting of [`settings`] on `base` (whose decimation is the reference's);
/// `on_row` hears of each row as it is measured.
pub fn cost_of_accuracy(
    base: &RunConfig,
    control: &RunControl,
    mut on_row: impl FnMut(&CostRow),
) -> Result<Vec<CostRow>, StudyError> {
    let mut rows = Vec::new();
    let mut reference: Option<(RunOutput, f64)> = None;
    for setting in settings(base.fidelity.decimation) {
        let config = apply(base, &setting.set)
            .map_err(|m| StudyError::Invalid(FieldError { field: setting.label.clone(), message: m }))?;
        let mut engine = Engine::new();
        let start = Instant::now();
        let run = engine.run(&config, control).map_err(|e| match e {
            EngineError::Cancelled => StudyError::Cancelled,
            other => StudyError::Run { instrument: config.instrument.name.clone(), message: other.to_string() },
        })?;
        let seconds = start.elapsed().as_secs_f64();
        let mae = chl_mae(&run);
        let row = match &reference {
            None => CostRow {
                label: setting.label,
                seconds,
                ratio: 1.0,
                chl_mae_pct: mae,
                delta_mae_pct: 0.0,
                chl_pixel_pct: Some(0.0),
                rrs_pixel_pct: Some(0.0),
            },
            Some((r, t)) => {
                let (chl, rrs) = per_pixel(&run, r);
                CostRow {
                    label: setting.label,
                    seconds,
                    ratio: seconds / t,
                    chl_mae_pct: mae,
                    delta_mae_pct: mae - chl_mae(r),
                    chl_pixel_pct: chl.map(|v| 100.0 * v),
                    rrs_pixel_pct: rrs.map(|v| 100.0 * v),
                }
            }
        };
        on_row(&row);
        rows.push(row);
        if reference.is_none() {
            reference = Some((run, seconds));
        }
    }
    Ok(rows)
}

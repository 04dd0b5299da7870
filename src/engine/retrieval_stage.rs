//! The retrieval stage: each configured retrieval over the Rrs image, scored against the truth.

use std::sync::Arc;

use super::cache::{Key, KeyBuilder, Stage};
use super::products::{RetrievalOutput, SceneSide};
use super::report::RunReport;
use super::run::Engine;
use super::{EngineError, RunConfig};
use crate::control::RunControl;
use crate::correction::Reflectance;
use crate::instrument::{Detector, DetectorMode, Truth};
use crate::retrieval::evaluate;
use crate::retrieval::run::band_responses;
use crate::retrieval::{Product, ProductFlags, RetrievalError, RetrievalInputs, RetrievalSpec, invert, prepare};
use crate::water::WaterGeometry;

/// Noise-equivalent ΔRrs per band at the typical radiance: the detector's noise (on, whatever
/// the run's switches: it characterises the instrument) in radiance, over the band's T_up·Ed
/// at the central column. Ideal instruments get a flat 1e-6 sr⁻¹ (uniform weighting).
fn nedr(config: &RunConfig, side: &SceneSide, typical: &[f64]) -> Vec<f64> {
    let detector = Detector::new(&config.instrument, &side.response, DetectorMode::default(), config.seed);
    let j = config.instrument.detectors / 2;
    let column = side.viewing.columns() / 2;
    (0..typical.len())
        .map(|b| {
            let k = detector.responsivity(j, b);
            let signal = k * typical[b];
            let noise = detector.variance_e2(b, signal, detector.dark_mean_e(j, b, detector.exposure_s())).sqrt();
            let t_ed = side.band_atmosphere.t_ed[side.band_atmosphere.at(column, b)];
            let v = noise / k / t_ed;
            if v.is_finite() && v > 0.0 { v } else { 1e-6 }
        })
        .collect()
}

impl Engine {
    /// Run every configured retrieval (cached under the Rrs it reads and its own settings).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn retrieval_stage(
        &mut self,
        config: &RunConfig,
        side: &SceneSide,
        truth: &Truth,
        (rrs, correction_key): (&Reflectance, Key),
        typical: &[f64],
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<Vec<Arc<RetrievalOutput>>, EngineError> {
        if config.retrievals.is_empty() {
            return Ok(Vec::new());
        }
        let nedr = nedr(config, side, typical);
        let column = side.viewing.columns() / 2;
        let bands = band_responses(&side.response, &side.band_atmosphere, column);
        let geometry: Vec<WaterGeometry> = side.viewing.looks[0]
            .iter()
            .map(|l| WaterGeometry {
                sun_zenith_rad: l.geometry.sun_zenith_rad,
                view_zenith_rad: l.geometry.view_zenith_rad,
            })
            .collect();
        let fail_in = |stage: Stage| {
            move |e: RetrievalError| match e {
                RetrievalError::Cancelled => EngineError::Cancelled,
                other => EngineError::Failed { stage, message: other.to_string() },
            }
        };
        let fail = fail_in(Stage::Retrieval);
        let scene_siop = side.scene.spec.siop.load(side.scene.base_dir.as_deref()).map_err(|e| fail(e.into()))?;
        let scene_substrates: Vec<String> = side.scene.spec.substrates.iter().map(|s| s.name.clone()).collect();
        let mut out = Vec::with_capacity(config.retrievals.len());
        for spec in &config.retrievals {
            // A SIOP or substrate file the retrieval names, edited on disk, is a new retrieval.
            let files = super::files::fingerprint(spec, config.scene_dir.as_deref());
            // An external program the user has since allowed is a new retrieval (its refusal is
            // not kept), and so is a function registered again (new code under the same name).
            let allowed = match spec {
                RetrievalSpec::External(e) => {
                    (e.may_run(), e.function.as_deref().and_then(crate::retrieval::function::registration))
                }
                _ => (true, None),
            };
            let key = KeyBuilder::new(Stage::Retrieval)
                .after(correction_key)
                .after(side.band_key)
                .with(&nedr)
                .with(spec)
                .with(&files)
                .with(&allowed)
                .finish();
            let inputs = RetrievalInputs {
                rrs: &rrs.rrs,
                flags: &rrs.flags,
                surface: &truth.surface,
                bands: bands.clone(),
                geometry: geometry.clone(),
                nedr: nedr.clone(),
                scene_siop: scene_siop.clone(),
                scene_substrates: scene_substrates.clone(),
                base_dir: config.scene_dir.as_deref(),
            };
            // The model reads the bands, the scene's SIOP and substrates and the scene directory:
            // the band key covers the first three (it follows the scene, the responses and the
            // geometry), the directory and the files the retrieval names are added.
            let model_key = KeyBuilder::new(Stage::RetrievalModel)
                .after(side.band_key)
                .with(spec)
                .with(&config.scene_dir)
                .with(&files)
                .finish();
            let model = self
                .stage(model_key, report, control, || prepare(spec, &inputs).map_err(fail_in(Stage::RetrievalModel)))?;
            let result = self.stage(key, report, control, || {
                // A user's program that fails costs its own product, not the run's others.
                let (product, failure) = match invert(&model, &inputs, control) {
                    Ok(p) => (p, None),
                    Err(e @ RetrievalError::External { .. }) => (failed_product(spec, &inputs), Some(e.to_string())),
                    Err(e) => return Err(fail(e)),
                };
                let mut metrics = evaluate(&product, truth);
                // Extra products scored where the algorithm says what their truth is.
                let extra_truths = model.extra_truths(truth);
                for (key, want) in &extra_truths {
                    if let Some(m) = product.map(key) {
                        metrics.variables.push(score_map(&product, m, want, &truth.surface, key.clone()));
                    }
                }
                Ok(RetrievalOutput {
                    spec: spec.clone(),
                    product,
                    metrics,
                    bands: inputs.bands.clone(),
                    nedr: inputs.nedr.clone(),
                    failure,
                    extra_truths,
                })
            })?;
            out.push(result);
        }
        Ok(out)
    }
}

/// `retrieved` against `truth` over the water pixels: a pixel the product did not return counts as
/// not returned ([`crate::metrics::compare`]).
fn score_map(
    product: &Product,
    retrieved: &ndarray::Array2<f32>,
    truth: &ndarray::Array2<f32>,
    surface: &crate::instrument::SurfaceMap,
    key: String,
) -> crate::metrics::VariableMetrics {
    let mut got = Vec::new();
    let mut want = Vec::new();
    for ((r, c), &t) in truth.indexed_iter() {
        if surface.is_water(r, c) {
            got.push(product.returned(r, c).then(|| f64::from(retrieved[[r, c]])));
            want.push(Some(f64::from(t)));
        }
    }
    crate::metrics::VariableMetrics { variable: key, metrics: crate::metrics::compare(&got, &want) }
}

/// The product of a retrieval that returned nothing: every water pixel failed, and a map of
/// nothing (NaN) for each variable it promised, so each is scored as 0 % returned and its
/// requirement fails (without maps its rows and FAIL verdicts vanished from the tables).
fn failed_product(spec: &RetrievalSpec, inputs: &RetrievalInputs<'_>) -> Product {
    use crate::variable::key;
    let flags = inputs.surface.water_mask().mapv(|w| if w { ProductFlags::FAILED } else { ProductFlags::LAND });
    let nothing = ndarray::Array2::from_elem(flags.dim(), f32::NAN);
    let mut p = Product::bare(spec.name().to_string(), flags);
    for variable in spec.algorithm().variables() {
        let map = Some(nothing.clone());
        match variable.as_str() {
            key::CHL => p.chl_mg_m3 = map,
            key::NAP => p.nap_g_m3 = map,
            key::CDOM => p.cdom_per_m = map,
            key::DEPTH => p.depth_m = map,
            _ => p.extras.push((variable, nothing.clone())),
        }
    }
    p
}

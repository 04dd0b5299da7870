//! The correction stage: Level-1 to Rrs by the exact inversion, the paper's per-scene
//! approximation or the image-based correction (with its aerosol family, `correction::family`),
//! and the Rrs against the truth.

use std::sync::Arc;

use super::cache::{Key, KeyBuilder, Stage};
use super::keys::Inputs;
use super::lut_axes::lut_axes;
use super::products::{Corrected, CorrectionProduct, SceneSide};
use super::report::RunReport;
use super::run::Engine;
use super::stages::failed;
use super::{EngineError, RunConfig};
use crate::calibration::Level1;
use crate::control::RunControl;
use crate::correction::{
    AerosolFamily, BandDifference, ExactTerms, FamilyLuts, Reflectance, RrsFlags, SceneApproximation, TruthRrsSample,
    compare_with_truth, correct_exact, correct_image, screen_image,
};
use crate::instrument::{AotNodes, SurfaceMap, Truth};
use ndarray::Array2;

impl Engine {
    /// Atmospheric correction: the delivered Rrs and the diagnostics.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn correction_stage(
        &mut self,
        config: &RunConfig,
        side: &SceneSide,
        (truth, truth_rrs, radiance_key): (&Truth, &TruthRrsSample, Key),
        approximation: Option<SceneApproximation>,
        (level1, level1_key): (Option<Arc<Level1>>, Key),
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<(Arc<Corrected>, Key), EngineError> {
        let fid = &config.fidelity;
        let inputs = Inputs::of(config);
        let Some(level1) = level1 else {
            return Err(EngineError::Failed { stage: Stage::Correction, message: "no Level-1 to correct".into() });
        };
        let band_key = side.band_key;
        // Atmospheric correction.
        let correction_key = KeyBuilder::new(Stage::Correction)
            .after(level1_key)
            .after(band_key)
            .after(radiance_key)
            .with(&config.correction)
            .with(&inputs.seed)
            .with(&inputs.decimation)
            .finish();
        let family = self.aerosol_family(config, side, control, report)?;
        let correction_key = match &family {
            Some((_, key)) => KeyBuilder::new(Stage::Correction).after(correction_key).after(*key).finish(),
            None => correction_key,
        };
        let correction = self.stage(correction_key, report, control, || {
            let fail = failed(Stage::Correction);
            // A preview computes only the product it shows; the diagnostics (the approximation
            // against the exact correction, and both against the truth) come with full resolution.
            let diagnostics = fid.decimation == 1;
            // The product each method delivers (the image-based one through the family above); a
            // new method is an arm here.
            let per_scene = match &config.correction.method {
                crate::correction::Method::Exact | crate::correction::Method::Image(_) => false,
                crate::correction::Method::PerScene => true,
            };
            // Where the scene has clouds, the processor screens them and their shadows out: the
            // image-based correction with its own test, the exact one knowing them exactly.
            let screen = cloud_screen(config, side, family.as_ref().map(|(f, _)| &**f), &level1, truth)?;
            let screened = screen.as_ref().map(|s| truth.surface.as_screened(s));
            let surface = screened.as_ref().unwrap_or(&truth.surface);
            // Nothing reads the Level-1 after the image-based correction: handed over where
            // nothing else holds it, it becomes the Rrs (one cube where there were two).
            let (image, level1) = match (&family, config.correction.image()) {
                (Some((fam, _)), Some(settings)) => {
                    let bands = &side.response.bands;
                    (Some(correct_image(level1, fam, settings, bands, surface, control).map_err(&fail)?), None)
                }
                _ => (None, Some(level1)),
            };
            // The image-based product is compared with the truth; the exact and approximate
            // corrections are not run beside it (`shoal budget` prices the difference).
            let against_truth = diagnostics;
            let diagnostics = diagnostics && image.is_none();
            let aerosol_map = side.aerosol_map.as_deref().zip(truth.aot550.as_ref());
            let modes = (diagnostics, per_scene);
            let model =
                model_based(config, side, (level1, surface, aerosol_map), approximation.as_ref(), modes, control)?;
            let approximation_vs_exact = model.approximation_vs_exact;
            let image_ran = image.is_some();
            let (image, aerosol) = image.map_or((None, None), |(r, a)| (Some(r), Some(a)));
            let Some(mut rrs) = image.or(model.rrs) else {
                return Err(EngineError::Failed { stage: Stage::Correction, message: "no correction ran".into() });
            };
            // The image-based correction masks high glint itself.
            let exact_high_glint =
                if image_ran { None } else { mask_exact_high_glint(config, side, &mut rrs, surface) };
            if let Some(screen) = &screen {
                mark_screened(&mut rrs, screen);
            }
            let rrs_vs_truth = if against_truth { compare_with_truth(&rrs, truth_rrs) } else { Vec::new() };
            let family = family.as_ref().map(|(f, _)| f.clone());
            let names: Vec<String> = side.response.bands.bands.iter().map(|b| b.name.clone()).collect();
            let rrs_metrics =
                crate::correction::band_rrs_metrics(&rrs, truth_rrs, &names, &side.response.bands.centres_nm());
            let product = CorrectionProduct {
                approximation,
                approximation_vs_exact,
                rrs_vs_truth,
                rrs_metrics,
                aerosol,
                family,
                exact_high_glint,
            };
            Ok(Corrected { rrs: Arc::new(rrs), product: Arc::new(product) })
        })?;
        let product = &correction.product;
        report.approximation = product.approximation.clone();
        report.approximation_vs_exact = product.approximation_vs_exact.clone();
        report.rrs_vs_truth = product.rrs_vs_truth.clone();
        report.aerosol = match (&product.aerosol, config.correction.image()) {
            (Some(a), Some(settings)) => Some(super::report::aerosol_summary(
                a,
                settings,
                &config.scene.atmosphere,
                truth.aot550.as_ref(),
                &side.response.bands.centres_nm(),
            )),
            _ => None,
        };
        report.exact_high_glint = product.exact_high_glint;
        Ok((correction, correction_key))
    }

    /// The image-based correction's family and its key, when the run asks for the
    /// image-based correction: its atmospheres once per scene atmosphere and LUT axes (two
    /// instruments with the same axes share them), its band terms once per instrument geometry.
    /// Neither depends on the scene's true aerosol.
    fn aerosol_family(
        &mut self,
        config: &RunConfig,
        side: &SceneSide,
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<Option<(Arc<AerosolFamily>, Key)>, EngineError> {
        let Some(image) = config.correction.image() else { return Ok(None) };
        let fid = &config.fidelity;
        let axes = lut_axes(&side.response, &side.viewing, config.scene.sun.zenith_deg, fid);
        let mut atmosphere = config.scene.atmosphere.clone();
        atmosphere.day_of_year = side.scene.day_of_year;
        (atmosphere.aerosol, atmosphere.aot550) = (crate::atmosphere::AerosolType::None, 0.0);
        let luts_key = KeyBuilder::new(Stage::AerosolLuts)
            .with(&atmosphere)
            .with(&axes)
            .with(&image.models)
            .with(&image.aot_nodes)
            .with(&image.glint_wind_error_m_s)
            .finish();
        let luts = self.stage(luts_key, report, control, || {
            FamilyLuts::build(image, &atmosphere, &axes, control).map_err(failed(Stage::AerosolLuts))
        })?;
        let key = KeyBuilder::new(Stage::AerosolFamily)
            .after(luts_key)
            .after(side.geometry_key)
            .with(&side.scene.spec.effects)
            .finish();
        // A preview computes the terms at fewer columns across the swath (its own key: the geometry's).
        let columns = crate::instrument::band_atmosphere::term_columns(fid.decimation);
        let fam = self.stage(key, report, control, || {
            AerosolFamily::tabulate(&luts, &side.scene, &side.response, &side.viewing, Some(columns), control)
                .map_err(failed(Stage::AerosolFamily))
        })?;
        Ok(Some((fam, key)))
    }
}

/// The AOT nodes' terms and the AOT under each pixel, where the scene's AOT is a map.
type AerosolMap<'a> = Option<(&'a AotNodes, &'a Array2<f32>)>;

/// What the corrections that invert with the model's own atmosphere make: the product (the
/// exact correction or the per-scene approximation), and the approximation's diagnostic against
/// the exact correction.
struct ModelBased {
    rrs: Option<Reflectance>,
    approximation_vs_exact: Vec<BandDifference>,
}

/// The exact or per-scene correction of `level1` (`None`: the image-based correction took it,
/// and neither runs) as the run asks for it, and at full resolution (`diagnostics`) the
/// approximation against the exact correction.
///
/// The diagnostic is always against the exact correction with the scene's own glint (whatever
/// wind the exact product assumes), and both sides are made pixel by pixel from the Level-1 as
/// the comparison reads them ([`SceneApproximation::compare_with_exact`]), so neither is held
/// whole for it. It runs first; the product then takes the Level-1 (where nothing else holds
/// it, its Rrs is written over it).
fn model_based(
    config: &RunConfig,
    side: &SceneSide,
    (level1, surface, aerosol_map): (Option<Arc<Level1>>, &SurfaceMap, AerosolMap<'_>),
    approximation: Option<&SceneApproximation>,
    (diagnostics, per_scene): (bool, bool),
    control: &RunControl,
) -> Result<ModelBased, EngineError> {
    let fail = failed(Stage::Correction);
    let Some(level1) = level1 else { return Ok(ModelBased { rrs: None, approximation_vs_exact: Vec::new() }) };
    let atmosphere = side.band_atmosphere.as_ref();
    let (rows, cols, nb) = level1.radiance.dim();
    // With no approximation (the image holds no water) the per-scene product is every pixel left
    // out, and the diagnostic compares that with the exact correction.
    let approximation_vs_exact = if diagnostics && (approximation.is_some() || per_scene) {
        let terms = ExactTerms::new((atmosphere, None), aerosol_map, surface, (cols, nb)).map_err(&fail)?;
        let compared = match approximation {
            Some(a) => a.compare_with_exact(&level1, surface, &terms),
            None => crate::correction::no_water_compared_with_exact(&level1, &terms),
        };
        compared.ok_or_else(|| EngineError::Failed {
            stage: Stage::Correction,
            message: format!("the Level-1 ({rows} × {cols} × {nb}) is not in standard layout"),
        })?
    } else {
        Vec::new()
    };
    let rrs = if per_scene {
        match approximation {
            Some(a) => a.correct(level1, surface, control),
            None => crate::correction::no_water(&level1),
        }
    } else {
        // The exact correction takes away the glint of the wind it assumes (`None`: the scene's
        // own).
        let expected = exact_glint(config, side);
        correct_exact(level1, (atmosphere, expected.as_deref()), aerosol_map, surface, control)
    };
    Ok(ModelBased { rrs: Some(rrs.map_err(&fail)?), approximation_vs_exact })
}

/// The glint the exact correction takes away when its wind is not the scene's
/// (`correction.glint_wind_error_m_s`) over a scene with glint: the scene's glint carried to the
/// wind it assumes ([`crate::correction::expected_glint`]). `None`: the scene's own glint.
fn exact_glint(config: &RunConfig, side: &SceneSide) -> Option<Vec<f64>> {
    if config.correction.exact_wind_error_m_s() == 0.0 {
        return None;
    }
    let winds = exact_winds(config, side)?;
    let n = config.scene.atmosphere.water_refractive_index;
    Some(crate::correction::expected_glint(&side.band_atmosphere, &side.viewing, &side.response, winds, n))
}

/// Over a scene with glint (a wind-roughened sea and `SunGlint`): the scene's wind and the one
/// the exact correction assumes (the scene's plus its error, at least 0), m/s.
fn exact_winds(config: &RunConfig, side: &SceneSide) -> Option<(f64, f64)> {
    let crate::atmosphere::SeaSurface::Wind { speed_m_s } = config.scene.atmosphere.surface else { return None };
    side.scene
        .wants(crate::scene::Effect::SunGlint)
        .then(|| (speed_m_s, (speed_m_s + config.correction.exact_wind_error_m_s()).max(0.0)))
}

/// Where the scene has clouds, the pixels the processor screens out (clouds and their shadows):
/// the image-based correction's own test with its family's Rayleigh member, the exact correction
/// knowing them exactly. `None` without clouds.
fn cloud_screen(
    config: &RunConfig,
    side: &SceneSide,
    family: Option<&AerosolFamily>,
    level1: &crate::calibration::Level1,
    truth: &Truth,
) -> Result<Option<ndarray::Array2<bool>>, EngineError> {
    if config.scene.clouds.is_none() {
        return Ok(None);
    }
    let (Some(fam), Some(settings)) = (family, config.correction.image()) else {
        return Ok(Some(truth.surface.exact_screen()));
    };
    let sun = crate::correction::Sun {
        zenith_rad: config.scene.sun.zenith_deg.to_radians(),
        azimuth_rad: config.scene.sun.azimuth_deg.to_radians(),
    };
    let rayleigh = fam
        .terms
        .first()
        .and_then(|m| m.first())
        .ok_or_else(|| EngineError::Failed { stage: Stage::Correction, message: "the family has no members".into() })?;
    let (bands, viewing, clouds) = (&side.response.bands, &side.viewing, &settings.clouds);
    // The glint the correction takes away is taken away before the cloud test too, folded into
    // the Rayleigh member's path radiance as `correction::correct_image` folds it into every
    // member's.
    let folded;
    let rayleigh = if settings.glint && !fam.glint_lgn.is_empty() {
        let mut terms = rayleigh.clone();
        terms.fold_glint_into_path();
        folded = terms;
        &folded
    } else {
        rayleigh
    };
    let screen = screen_image(level1, rayleigh, bands, viewing, sun, clouds, &truth.surface)
        .map_err(failed(Stage::Correction))?;
    Ok(Some(screen))
}

/// The exact correction's high-glint mask, where its threshold is set and the scene glints: the
/// water pixels of the columns whose normalised glint L_GN, expected from the wind it assumes
/// (the scene's plus its error, at least 0), exceeds the threshold are left out of `rrs`.
fn mask_exact_high_glint(
    config: &RunConfig,
    side: &SceneSide,
    rrs: &mut crate::correction::Reflectance,
    surface: &crate::instrument::SurfaceMap,
) -> Option<super::HighGlint> {
    let threshold_per_sr = config.correction.exact_glint_threshold_per_sr()?;
    let (_, assumed_wind_m_s) = exact_winds(config, side)?;
    let n = config.scene.atmosphere.water_refractive_index;
    let lgn = crate::correction::column_lgn(&side.viewing, assumed_wind_m_s, n);
    let high = |c: usize| lgn.get(c).is_some_and(|g| *g > threshold_per_sr);
    let pixels = crate::correction::mark_high_glint(rrs, &high, surface);
    Some(super::HighGlint { pixels, water_pixels: surface.water_count(), threshold_per_sr, assumed_wind_m_s })
}

/// Flag every band of the pixels the cloud screen left out (`screen` true) as cloud.
fn mark_screened(rrs: &mut crate::correction::Reflectance, screen: &ndarray::Array2<bool>) {
    for ((r, c), _) in screen.indexed_iter().filter(|(_, s)| **s) {
        for b in 0..rrs.flags.dim().2 {
            rrs.flags[[r, c, b]] |= RrsFlags::CLOUD | RrsFlags::INVALID;
            rrs.rrs[[r, c, b]] = 0.0;
        }
    }
}

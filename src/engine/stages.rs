//! The stages of the chain from the scene to the SNR table, as `Engine` methods: each builds its
//! cache key from exactly the inputs that decide its product, so a change re-runs only the stages
//! downstream of it (retrievals and metrics are in `products.rs`).

use std::sync::Arc;

use super::cache::{Key, KeyBuilder, Stage};
use super::files;
use super::keys::Inputs;
use super::lut_axes::lut_axes;
use super::products::{InstrumentSide, SceneSide};
use super::report::{RunReport, SkippedEffect};
use super::run::Engine;
use super::{EngineError, RunConfig};
use crate::atmosphere::AtmosphereLut;
use crate::calibration::{Calibration, FocalKnowledge, band_e0, calibrate, calibrate_owned};
use crate::control::Cancellable;
use crate::control::RunControl;
use crate::instrument::compression::compress_level0;
use crate::instrument::effects::{self, MtfBudget};
use crate::instrument::feasibility::Feasibility;
use crate::instrument::sample::BandAtmosphere;
use crate::instrument::{
    Detector, Level0, RadianceCube, Response, SampleOptions, SnrRow, SpatialKernel, Viewing, analytic_snr,
    digitise_cube, expose_and_digitise, expose_cube, measured_snr, sample_radiance,
};
use crate::scene::{Effect, Scene};
use crate::toa::SceneOptics;

/// A stage's error as the engine reports it: cancellation stays cancellation, anything else
/// names the stage.
pub(super) fn failed<E: Cancellable + std::fmt::Display>(stage: Stage) -> impl Fn(E) -> EngineError {
    move |e| {
        if e.is_cancelled() { EngineError::Cancelled } else { EngineError::Failed { stage, message: e.to_string() } }
    }
}

pub(super) fn failed_any<E: std::fmt::Display>(stage: Stage) -> impl Fn(E) -> EngineError {
    move |e| EngineError::Failed { stage, message: e.to_string() }
}

impl Engine {
    /// Scene, response, geometry, LUT, optics and the band-effective atmosphere.
    pub(super) fn scene_side(
        &mut self,
        config: &RunConfig,
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<SceneSide, EngineError> {
        let instrument = &config.instrument;
        let fid = &config.fidelity;
        let inputs = Inputs::of(config);
        // The files the configuration names, by contents (or, for large ones, length, times and
        // inode; [`super::files`]): a file edited on disk changes the key of the stage that reads it
        // (and so every key after it), as an edit of the configuration would.
        let scene_dir = config.scene_dir.as_deref();
        // Scene.
        let scene_key = KeyBuilder::new(Stage::Scene)
            .with(&config.scene)
            .with(&config.scene_dir)
            .with(&files::fingerprint(&config.scene, scene_dir))
            .finish();
        let scene = self.stage(scene_key, report, control, || {
            Scene::build(&config.scene, config.scene_dir.as_deref()).map_err(failed_any(Stage::Scene))
        })?;
        // A design's own MTF budget samples with its PSF whatever the scene says.
        let states_mtf = effects::spatial_response(&config.instrument.effects).is_some();
        for effect in Effect::ALL {
            let wanted = scene.wants(effect) || (effect == Effect::SpatialResponse && states_mtf);
            if !wanted {
                report.skipped_effects.push(SkippedEffect { effect, reason: "not asked for by the scene".into() });
            }
        }

        // Spectral response.
        let response_key = KeyBuilder::new(Stage::Response)
            .with(&inputs.response)
            .with(&files::fingerprint(&config.instrument, scene_dir))
            .finish();
        let response = self.stage(response_key, report, control, || {
            Response::new(instrument, fid.spectral_step_nm).map_err(failed(Stage::Response))
        })?;
        report.grid_points = response.groups.iter().map(|g| g.grid.len()).collect();
        let sensed_response = self.sensed_response(config, response_key, control, report)?;

        // Geometry.
        let sun = config.scene.sun;
        let geometry_key =
            KeyBuilder::new(Stage::Geometry).after(response_key).after(scene_key).with(&inputs.orbit).finish();
        let viewing = self.stage(geometry_key, report, control, || {
            Viewing::new(
                instrument,
                &response,
                sun.zenith_deg.to_radians(),
                sun.azimuth_deg.to_radians(),
                fid.decimation,
                Some(scene.extent.half_size_m()),
            )
            .map_err(failed(Stage::Geometry))
        })?;
        report.cropped = viewing.cropped;
        report.line_period_s = viewing.line_period_s;

        // Atmosphere LUT: wavelength nodes on a fixed lattice covering the grids, one sun node,
        // view nodes up to the swath edge.
        let axes = lut_axes(&response, &viewing, sun.zenith_deg, fid);
        let mut atmosphere_spec = config.scene.atmosphere.clone();
        atmosphere_spec.day_of_year = scene.day_of_year;
        let lut_key = KeyBuilder::new(Stage::Lut).with(&atmosphere_spec).with(&axes).finish();
        let lut = self.stage(lut_key, report, control, || {
            let atmosphere = atmosphere_spec.build().map_err(failed_any(Stage::Lut))?;
            AtmosphereLut::build(&atmosphere, axes.clone()).map_err(failed_any(Stage::Lut))
        })?;

        // Optics: the scene on each group's grid.
        let optics_key = KeyBuilder::new(Stage::Optics)
            .after(scene_key)
            .after(lut_key)
            .after(response_key)
            .with(&inputs.band_nodes)
            .with(&inputs.water_single_precision)
            .finish();
        let optics = self.stage(optics_key, report, control, || {
            response
                .groups
                .iter()
                .enumerate()
                .map(|(gi, g)| {
                    let optics = SceneOptics::new(&scene, &g.grid, lut.clone())?;
                    if fid.band_nodes == 0 {
                        Ok(optics)
                    } else {
                        // Nodes under the believed bands and the true ones.
                        let mut nodes = response.band_nodes(gi, fid.band_nodes);
                        if let Some(sensed) = &sensed_response {
                            nodes.extend(sensed.band_nodes(gi, fid.band_nodes));
                            nodes.sort_unstable();
                            nodes.dedup();
                        }
                        optics.with_band_nodes(nodes, fid.water_single_precision)
                    }
                })
                .collect::<Result<Vec<_>, _>>()
                .map_err(failed_any(Stage::Optics))
        })?;

        let band_key = KeyBuilder::new(Stage::BandAtmosphere).after(optics_key).after(geometry_key).finish();
        let band_atmosphere = self.stage(band_key, report, control, || {
            BandAtmosphere::new(&optics, &viewing, &response).map_err(failed(Stage::BandAtmosphere))
        })?;

        // The AOT range under the pixels is the scene's and the geometry's: keyed after the
        // stated band atmosphere, and found once for both sets of bands.
        let range_after = band_key;
        let (aerosol_map, band_key) = self.aerosol_map_stage(
            (&scene, &response, &viewing),
            (&atmosphere_spec, &axes),
            (band_key, range_after),
            control,
            report,
        )?;
        // The same through the bands the instrument really has: what the scene is sampled with.
        let sensed = self.sensed_side(
            sensed_response,
            (&scene, &optics, &viewing),
            (&atmosphere_spec, &axes),
            (band_key, range_after),
            control,
            report,
        )?;

        Ok(SceneSide {
            scene,
            response,
            response_key,
            viewing,
            geometry_key,
            optics,
            band_atmosphere,
            aerosol_map,
            band_key,
            sensed,
        })
    }

    /// The pupil radiance and the truth (the spatial response only when the scene asks for it).
    pub(super) fn radiance_stage(
        &mut self,
        config: &RunConfig,
        side: &SceneSide,
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<(Arc<RadianceCube>, Key), EngineError> {
        let instrument = &config.instrument;
        let fid = &config.fidelity;
        let inputs = Inputs::of(config);
        let SceneSide { scene, response, viewing, optics, band_atmosphere, .. } = side;
        // The scene is sampled through the bands the instrument has; the truth through the
        // stated ones (what the products claim to be).
        let (sampled_response, sampled_atmosphere, aerosol_map, band_key) = side.sampled();
        // The design's own MTF budget; else, where the scene asks for a spatial response (the
        // legacy switch), an ideal optic's.
        let ideal = MtfBudget::default();
        let budget = effects::spatial_response(&instrument.effects)
            .or_else(|| scene.wants(Effect::SpatialResponse).then_some(&ideal));
        let kernel = match budget {
            Some(b) => SpatialKernel::new(instrument, b, &response.bands.centres_nm(), fid.spatial_samples_per_gsd),
            None => SpatialKernel::point(response.n_bands()),
        };
        report.spatial_samples = kernel.len();
        let radiance_key = KeyBuilder::new(Stage::Radiance)
            .after(band_key)
            .with(&kernel.offsets_m)
            .with(&kernel.weights)
            .with(&inputs.heading_deg)
            .finish();
        let executed_before = self.executions(Stage::Radiance);
        let radiance = self.stage(radiance_key, report, control, || {
            let options = SampleOptions { kernel: kernel.clone(), heading_deg: instrument.heading_deg };
            let atmospheres = (sampled_atmosphere.as_ref(), aerosol_map, band_atmosphere.as_ref());
            sample_radiance(scene, optics, viewing, sampled_response, atmospheres, &options, control)
                .map_err(failed(Stage::Radiance))
        })?;
        if self.executions(Stage::Radiance) > executed_before {
            report.water_evaluations = radiance.water_evaluations;
            report.bottom_evaluations = radiance.bottom_evaluations;
        }
        let (rows, cols, nb) = radiance.radiance.dim();
        report.shape = (rows, cols, nb);
        report.truth_shares = radiance.truth_shares.clone();

        Ok((radiance, radiance_key))
    }

    /// Detector, electrons, Level-0, calibration and Level-1.
    pub(super) fn instrument_side(
        &mut self,
        config: &RunConfig,
        side: &SceneSide,
        radiance: Arc<RadianceCube>,
        radiance_key: Key,
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<InstrumentSide, EngineError> {
        let instrument = &config.instrument;
        let SceneSide { scene, response, response_key, viewing, optics, .. } = side;
        let response_key = *response_key;
        // Detector, electrons, Level-0.
        let inputs = Inputs::of(config);
        // The focal-plane effects the detector carries: as applied for the detector and its
        // electrons, with the processor's knowledge for the calibration.
        let on_the_detector = effects::on_the_detector(&instrument.effects);
        let applied: Vec<_> = on_the_detector.iter().map(effects::InstrumentEffect::as_applied).collect();
        let detector_key = KeyBuilder::new(Stage::Detector)
            .after(response_key)
            .with(&inputs.photon)
            .with(&inputs.electronics)
            .with(&applied)
            .finish();
        // The detector's bands are those the instrument has.
        let detector = self.stage(detector_key, report, control, || {
            Ok(Detector::new(instrument, side.sampled().0, config.detector, config.seed))
        })?;
        // Feasibility: the detector over this scene's brightest water, at this line period.
        let feasibility_key = KeyBuilder::new(Stage::Feasibility).after(detector_key).after(radiance_key).finish();
        let feasibility = self.stage(feasibility_key, report, control, || {
            let names: Vec<String> = response.bands.bands.iter().map(|b| b.name.clone()).collect();
            Ok(Feasibility::assess(
                instrument,
                &detector,
                &names,
                &response.bands.centres_nm(),
                &radiance.brightest_water_w_m2_sr_nm,
                viewing.line_period_s,
            ))
        })?;
        report.warnings.clone_from(&feasibility.warnings);
        // The optics between pupil and detector (none: the detector sees the pupil radiance).
        let (at_detector, optics_key) = self.effects_stage(config, side, &radiance, radiance_key, control, report)?;
        let detector_radiance = at_detector.as_deref().unwrap_or(&radiance.radiance);
        let electrons_key = KeyBuilder::new(Stage::Electrons)
            .after(optics_key)
            .after(response_key)
            .with(&inputs.photon)
            .with(&applied)
            .finish();
        // On-board compression codes the counts as the Level-0 stage makes them.
        let compression = effects::compression(&instrument.effects).copied();
        let level0_key =
            KeyBuilder::new(Stage::Level0).after(electrons_key).with(&inputs.electronics).with(&compression).finish();
        let coded = |mut level0: Level0| match &compression {
            Some(c) => compress_level0(&mut level0, &detector, c, control).map(|_| level0),
            None => Ok(level0),
        };
        let level0 = if self.keeps_cubes() {
            // The electrons kept apart, so that a change of the electronics reruns only the readout.
            let electrons = self.stage(electrons_key, report, control, || {
                expose_cube(&detector, detector_radiance, viewing, config.seed, control)
                    .map_err(failed(Stage::Electrons))
            })?;
            self.stage(level0_key, report, control, || {
                digitise_cube(&detector, &electrons, viewing, config.seed, control)
                    .and_then(coded)
                    .map_err(failed(Stage::Level0))
            })?
        } else {
            // A lean run keeps no electrons cube: exposure and readout row by row (the same counts).
            self.stage(level0_key, report, control, || {
                expose_and_digitise(&detector, detector_radiance, viewing, config.seed, control)
                    .and_then(coded)
                    .map_err(failed(Stage::Level0))
            })?
        };
        // The pupil radiance is let go once the detector has seen it, unless the run keeps it, and
        // the radiance at the detector with it (the cache may keep it, within its budget).
        drop(at_detector);
        let radiance = self.keeps_cubes().then_some(radiance);
        (report.saturated, report.zero_counts) = (level0.saturated, level0.zero_counts);
        report.compression = level0.compression;

        // Calibration and Level-1.
        let calibration_key = KeyBuilder::new(Stage::Calibration)
            .after(detector_key)
            .with(&config.calibration)
            .with(&scene.day_of_year)
            .with(&inputs.seed)
            .with(&viewing.detector_index)
            .with(&on_the_detector)
            .finish();
        let calibration = self.stage(calibration_key, report, control, || {
            let e0: Vec<Vec<f64>> = optics.iter().map(|o| o.e0().to_vec()).collect();
            // The diffuser as the processor believes the bands see it, and as they do (the same
            // unless the instrument states a spectral knowledge error).
            let believed = band_e0(response, instrument.detectors, &e0);
            let sensed = side.sensed.as_ref().map(|s| band_e0(&s.response, instrument.detectors, &e0));
            let e0_band = (sensed.as_deref().unwrap_or(&believed), believed.as_slice());
            let knowledge = FocalKnowledge::of(&instrument.effects);
            let used = &viewing.detector_index;
            Calibration::derive(&config.calibration, (&detector, knowledge), e0_band, used, config.seed)
                .map_err(failed(Stage::Calibration))
        })?;
        report.diffuser_incidence_deg = calibration.sun_incidence_deg;
        report.diffuser_saturated_frames = calibration.saturated_frames;
        let level1_key =
            KeyBuilder::new(Stage::Level1).after(level0_key).after(calibration_key).with(&inputs.effects).finish();
        let kept_level0 = self.keeps_cubes().then(|| level0.clone());
        let level1 = self.stage(level1_key, report, control, || {
            // Where nothing else holds the Level-0 (a run that keeps no cubes, whose cache let it
            // go), its flags become the Level-1's and its counts go once they are read.
            let level1 = match Arc::try_unwrap(level0) {
                Ok(own) => calibrate_owned(own, &calibration, viewing, control),
                Err(shared) => calibrate(&shared, &calibration, viewing, control),
            };
            let mut level1 = level1.map_err(failed(Stage::Level1))?;
            super::effects_stage::correct_level1(config, side, &mut level1.radiance, control)?;
            Ok(level1)
        })?;

        Ok(InstrumentSide {
            radiance,
            detector,
            detector_key,
            feasibility,
            level0: kept_level0,
            calibration,
            level1: Some(level1),
            level1_key,
        })
    }

    /// SNR at the scene's typical (median water) radiance.
    pub(super) fn snr_stage(
        &mut self,
        config: &RunConfig,
        side: &SceneSide,
        typical: Vec<f64>,
        inst: &InstrumentSide,
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<(Arc<Vec<SnrRow>>, Vec<f64>), EngineError> {
        let (instrument, fid, response) = (&config.instrument, &config.fidelity, &side.response);
        let inputs = Inputs::of(config);
        let (detector, detector_key) = (&inst.detector, inst.detector_key);
        let nb = response.n_bands();
        // The SNR at the user's reference radiance when one is set (the retrievals keep
        // weighting by the scene's own typical radiance).
        let at = match &config.snr_reference {
            Some(reference) => {
                reference_radiance(reference, &response.bands.centres_nm(), config.scene_dir.as_deref())?
            }
            None => typical.clone(),
        };
        let snr_key = KeyBuilder::new(Stage::Snr).after(detector_key).with(&at).with(&inputs.snr).finish();
        let snr = self.stage(snr_key, report, control, || {
            // A preview measures on fewer detectors (the estimate's spread grows as √decimation).
            let n = instrument.detectors;
            let m = (fid.snr_detectors / fid.decimation).clamp(1, n);
            let picks: Vec<usize> = (0..m).map(|i| (2 * i + 1) * n / (2 * m)).collect();
            let centres = response.bands.centres_nm();
            let measured = measured_snr(detector, &at, &picks, fid.snr_frames, config.seed);
            let full = |b: usize| crate::instrument::plausibility::full_scale_e(detector, b);
            Ok((0..nb)
                .map(|b| SnrRow {
                    band: response.bands.bands[b].name.clone(),
                    centre_nm: centres[b],
                    radiance: at[b],
                    snr_analytic: analytic_snr(detector, n / 2, b, at[b]),
                    snr_measured: measured[b],
                    full_scale_fraction: crate::instrument::plausibility::peak_signal_e(detector, b, at[b])
                        / full(b).max(f64::MIN_POSITIVE),
                })
                .collect::<Vec<_>>())
        })?;
        Ok((snr, typical))
    }
}

/// The reference radiance at each band centre, W m⁻² sr⁻¹ nm⁻¹ (the spectrum is stated per µm, as
/// missions state it); every value must be positive and finite.
fn reference_radiance(
    reference: &crate::spectral::SpectrumSource,
    centres_nm: &[f64],
    dir: Option<&std::path::Path>,
) -> Result<Vec<f64>, EngineError> {
    let fail =
        |message: String| EngineError::Failed { stage: Stage::Snr, message: format!("snr_reference: {message}") };
    let mut sorted = centres_nm.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    let grid = crate::spectral::WavelengthGrid::from_wavelengths(sorted.clone()).map_err(|e| fail(e.to_string()))?;
    let values =
        reference.sample(&grid, crate::spectral::Extrapolation::Clamp, dir).map_err(|e| fail(e.to_string()))?;
    centres_nm
        .iter()
        .map(|c| {
            let i = sorted.iter().position(|s| s == c).unwrap_or(0);
            let v = values[i];
            if v.is_finite() && v > 0.0 && v <= 1e4 {
                Ok(v / 1000.0)
            } else {
                Err(fail(format!("{v} W m⁻² sr⁻¹ µm⁻¹ at {c:.0} nm (allowed: above 0, at most 10000)")))
            }
        })
        .collect()
}

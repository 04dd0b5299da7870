//! The scene side's stages beyond the stated response and its band atmosphere: the band terms
//! at AOT nodes where the scene's AOT is a map, and the bands the instrument really has (their
//! response, band atmosphere and AOT nodes) where the processor's knowledge of them is wrong.

use std::sync::Arc;

use super::cache::{Key, KeyBuilder, Stage};
use super::products::Sensed;
use super::report::RunReport;
use super::run::Engine;
use super::stages::{failed, failed_any};
use super::{EngineError, RunConfig};
use crate::atmosphere::{AtmosphereLut, AtmosphereSpec, LutAxes};
use crate::control::RunControl;
use crate::instrument::aerosol_map;
use crate::instrument::effects;
use crate::instrument::sample::BandAtmosphere;
use crate::instrument::{AotNodes, Response, Viewing};
use crate::scene::Scene;
use crate::toa::{PathOptics, SceneOptics};

impl Engine {
    /// The bands the instrument really has, where the processor's knowledge of them is wrong
    /// (`None` otherwise). The response key holds the error: the same grids, other weights.
    pub(super) fn sensed_response(
        &mut self,
        config: &RunConfig,
        response_key: Key,
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<Option<Arc<Response>>, EngineError> {
        if effects::spectral_knowledge(&config.instrument.effects).is_none() {
            return Ok(None);
        }
        let key = KeyBuilder::new(Stage::Response).after(response_key).with("sensed").finish();
        let response = self.stage(key, report, control, || {
            Response::sensed(&config.instrument, config.fidelity.spectral_step_nm).map_err(failed(Stage::Response))
        })?;
        Ok(Some(response))
    }

    /// Where the instrument states a spectral knowledge error (`sensed_response`, its true
    /// bands): their band atmosphere and AOT nodes, keyed after the stated ones' (`band_key`),
    /// with the AOT range the stated bands' found (`range_after`, see [`Self::aerosol_map_stage`]).
    pub(super) fn sensed_side(
        &mut self,
        sensed_response: Option<Arc<Response>>,
        (scene, optics, viewing): (&Arc<Scene>, &Arc<Vec<SceneOptics>>, &Arc<Viewing>),
        (atmosphere_spec, axes): (&AtmosphereSpec, &LutAxes),
        (band_key, range_after): (Key, Key),
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<Option<Sensed>, EngineError> {
        let Some(response) = sensed_response else { return Ok(None) };
        let key = KeyBuilder::new(Stage::BandAtmosphere).after(band_key).with("sensed").finish();
        let band_atmosphere = self.stage(key, report, control, || {
            BandAtmosphere::new(optics, viewing, &response).map_err(failed(Stage::BandAtmosphere))
        })?;
        let (aerosol_map, band_key) = self.aerosol_map_stage(
            (scene, &response, viewing),
            (atmosphere_spec, axes),
            (key, range_after),
            control,
            report,
        )?;
        Ok(Some(Sensed { response, band_atmosphere, aerosol_map, band_key }))
    }

    /// A scene whose AOT varies: the band terms at AOT nodes spanning its map, each node's LUT
    /// cached as a scene with that constant AOT would cache it, after `band_key`; the AOT range
    /// under the pixels keyed after `range_after` (it follows the scene and the geometry, not
    /// the bands). Returns them (none without a map) and the key later stages build on.
    pub(super) fn aerosol_map_stage(
        &mut self,
        (scene, response, viewing): (&Arc<Scene>, &Arc<Response>, &Arc<Viewing>),
        (atmosphere_spec, axes): (&AtmosphereSpec, &LutAxes),
        (band_key, range_after): (Key, Key),
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<(Option<Arc<AotNodes>>, Key), EngineError> {
        if scene.aot550.is_none() {
            return Ok((None, band_key));
        }
        // The AOT under every pixel centre the image samples (the map's own range is sampled on
        // at most 512² cells and could miss a corner or a narrow peak); cached with the band
        // atmosphere, so a run that changes only the electronics does not walk the image again.
        let range_key = KeyBuilder::new(Stage::BandAtmosphere).after(range_after).with("aot550 range").finish();
        let range = self.stage(range_key, report, control, || {
            Ok((0..viewing.lines())
                .flat_map(|r| (0..viewing.columns()).map(move |c| (r, c)))
                .map(|(r, c)| {
                    let (x, y) = viewing.ground_m(0, r, c);
                    scene.aot550_at(x, y)
                })
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v))))
        })?;
        let (lo, hi) = *range;
        let nodes = aerosol_map::node_values(lo, hi.max(lo));
        let mut luts = Vec::with_capacity(nodes.len());
        let mut nodes_key = KeyBuilder::new(Stage::BandAtmosphere).after(band_key).with(&nodes);
        for &tau in &nodes {
            let spec = AtmosphereSpec { aot550: tau, ..atmosphere_spec.clone() };
            let key = KeyBuilder::new(Stage::Lut).with(&spec).with(axes).finish();
            luts.push(self.stage(key, report, control, || {
                let atmosphere = spec.build().map_err(failed_any(Stage::Lut))?;
                AtmosphereLut::build(&atmosphere, axes.clone()).map_err(failed_any(Stage::Lut))
            })?);
            nodes_key = nodes_key.after(key);
        }
        let nodes_key = nodes_key.finish();
        let at_nodes = self.stage(nodes_key, report, control, || {
            // Each node's atmosphere on the grids, without the water (the band terms read only
            // the path).
            let paths = luts
                .iter()
                .map(|lut| {
                    response
                        .groups
                        .iter()
                        .map(|g| PathOptics::new(scene, &g.grid, lut.clone()))
                        .collect::<Result<Vec<_>, _>>()
                })
                .collect::<Result<Vec<_>, _>>()
                .map_err(failed_any(Stage::BandAtmosphere))?;
            AotNodes::build(nodes.clone(), &paths, viewing, response).map_err(failed(Stage::BandAtmosphere))
        })?;
        Ok((Some(at_nodes), nodes_key))
    }
}

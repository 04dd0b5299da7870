//! The instrument's optical effects: applied to the pupil radiance before the detector sees it
//! (stage `Effects`), and undone on Level-1 as the processor knows them (inside `Level1`).
//! An instrument with no effects skips both: its keys and products are those of an ideal optic.

use std::sync::Arc;

use ndarray::Array3;

use super::cache::{Key, KeyBuilder, Stage};
use super::products::SceneSide;
use super::report::RunReport;
use super::run::Engine;
use super::stages::failed;
use super::{EngineError, RunConfig};
use crate::control::RunControl;
use crate::instrument::RadianceCube;
use crate::instrument::effects::{self, Context, StokesColumns};

/// The radiance reaching the detector when the optics change it (`None`: the pupil's).
pub(super) type AtDetector = Option<Arc<Array3<f32>>>;

/// The path's Q and U per column and band, when an effect of `config`'s instrument reads them.
fn stokes_for(config: &RunConfig, side: &SceneSide) -> Result<Option<StokesColumns>, EngineError> {
    if !effects::needs_stokes(&config.instrument.effects) {
        return Ok(None);
    }
    StokesColumns::build(
        &side.optics,
        &side.viewing,
        &side.response,
        &side.band_atmosphere,
        config.scene.sun.azimuth_deg.to_radians(),
        config.instrument.heading_deg.to_radians(),
    )
    .map(Some)
    .map_err(failed(Stage::Effects))
}

/// Run `f` with the effects' context of this run.
fn with_context<T>(
    config: &RunConfig,
    side: &SceneSide,
    f: impl FnOnce(&Context) -> Result<T, EngineError>,
) -> Result<T, EngineError> {
    let stokes = stokes_for(config, side)?;
    let spacing = side.viewing.gsd_m * side.viewing.decimation as f64;
    let centres = side.response.bands.centres_nm();
    let pixel_m = side.viewing.gsd_m;
    f(&Context { spacing_m: (spacing, spacing), pixel_m, centres_nm: &centres, stokes: stokes.as_ref() })
}

impl Engine {
    /// The radiance reaching the detector, when the instrument states effects (`None`: the
    /// pupil radiance itself), and the key later stages build on.
    pub(super) fn effects_stage(
        &mut self,
        config: &RunConfig,
        side: &SceneSide,
        radiance: &Arc<RadianceCube>,
        radiance_key: Key,
        control: &RunControl,
        report: &mut RunReport,
    ) -> Result<(AtDetector, Key), EngineError> {
        let list = &config.instrument.effects;
        if !effects::any_on_the_cube(list) {
            return Ok((None, radiance_key));
        }
        // Only the effects on the cube: the detector's and the coder's enter their own stages' keys.
        let applied: Vec<_> =
            list.iter().filter(|e| e.effect().on_the_cube()).map(effects::InstrumentEffect::as_applied).collect();
        let key = KeyBuilder::new(Stage::Effects).after(radiance_key).with(&applied).finish();
        let cube = self.stage(key, report, control, || {
            with_context(config, side, |ctx| {
                let mut cube = radiance.radiance.clone();
                effects::apply_all(list, &mut cube, ctx, control).map_err(failed(Stage::Effects))?;
                Ok(cube)
            })
        })?;
        Ok((Some(cube), key))
    }
}

/// The Level-1 processor's corrections of the instrument's effects, in place.
pub(super) fn correct_level1(
    config: &RunConfig,
    side: &SceneSide,
    level1: &mut Array3<f32>,
    control: &RunControl,
) -> Result<(), EngineError> {
    let list = &config.instrument.effects;
    if !effects::any_on_the_cube(list) {
        return Ok(());
    }
    with_context(config, side, |ctx| effects::correct_all(list, level1, ctx, control).map_err(failed(Stage::Level1)))
}

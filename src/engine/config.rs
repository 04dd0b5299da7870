//! A run's configuration: everything that decides its result, serialisable as the "fully
//! resolved configuration" written beside every output.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::calibration::CalibrationSpec;
use crate::correction::CorrectionSpec;
use crate::instrument::{DetectorMode, InstrumentError, InstrumentSpec};
use crate::parse::{FieldError, ParseError};
use crate::retrieval::RetrievalSpec;
use crate::scene::SceneSpec;

/// Fidelity settings: what accuracy is bought with time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Fidelity {
    /// Spectral step of the simulation grids, nm (0.1–10).
    pub spectral_step_nm: f64,
    /// Spatial-response quadrature points per GSD along each axis (1–8), when the instrument
    /// states an MTF budget (or the scene the legacy `SpatialResponse`).
    pub spatial_samples_per_gsd: usize,
    /// Per-pixel water spectra at this many nodes per band (0–8; 0: at every grid wavelength;
    /// default [`DEFAULT_BAND_NODES`]). A configuration file written before the field existed
    /// has a fidelity without it and reads 0, so it reproduces its results; a file without any
    /// fidelity gets the defaults.
    /// The pixel's Rrs is evaluated only at each band's response quantiles and interpolated
    /// linearly between them under the band; the atmosphere, the solar spectrum and the responses
    /// stay on the full grid (see [`crate::instrument::BandAtmosphere`]). Land and scenes with
    /// adjacency use the full grid.
    #[serde(default)]
    pub band_nodes: usize,
    /// Evaluate the per-pixel water spectra at the band nodes in single precision (`f32` lanes,
    /// [`crate::water::SingleWater`]: Rrs within 2·10⁻⁶ of the double-precision kernel, 2.0× its
    /// evaluations per second in shallow water at 451 wavelengths). On by default
    /// ([`DEFAULT_WATER_SINGLE_PRECISION`]); a configuration file whose fidelity has no such
    /// field reads `false`, so it reproduces its results. Only with band nodes (the full-grid
    /// path, the cost table's reference, stays in double precision).
    #[serde(default)]
    pub water_single_precision: bool,
    /// Preview decimation: every n-th line and detector (1 = full resolution).
    pub decimation: usize,
    /// Wavelength spacing of the atmosphere LUT nodes, nm (5–50); radiances are interpolated
    /// log–log between nodes, the 1-nm solar spectrum and gases are applied exactly.
    pub lut_wavelength_step_nm: f64,
    /// View-zenith spacing of the LUT nodes, degrees (1–20).
    pub lut_view_step_deg: f64,
    /// Frames of the simulated uniform patch that measures SNR (2–10 000).
    pub snr_frames: usize,
    /// Detectors of the SNR patch (spread across the swath), at most.
    pub snr_detectors: usize,
}

impl Default for Fidelity {
    fn default() -> Self {
        Self {
            spectral_step_nm: 1.0,
            spatial_samples_per_gsd: 2,
            band_nodes: DEFAULT_BAND_NODES,
            water_single_precision: DEFAULT_WATER_SINGLE_PRECISION,
            decimation: 1,
            lut_wavelength_step_nm: 20.0,
            lut_view_step_deg: 5.0,
            snr_frames: 128,
            snr_detectors: 256,
        }
    }
}

/// The default of [`Fidelity::band_nodes`], chosen from the cost table (`shoal bench
/// --accuracy`, CubeSat over Lake Hume, full resolution): the cheapest full-resolution setting
/// within 1 % chl error per pixel, on the Pareto front; 2 and 3 nodes per band were no faster
/// and erred more (the table: docs/RESULTS.md, "Cost of accuracy").
pub const DEFAULT_BAND_NODES: usize = 4;

/// The default of [`Fidelity::water_single_precision`], chosen from the cost table (`shoal bench
/// --accuracy --pareto --tolerance-pct 1`, CubeSat over Lake Hume, full resolution): with band
/// nodes, the single-precision kernel is on the Pareto front within 1 % chl error, with the same
/// chl error per pixel against the reference as double precision and no slower (the table:
/// docs/RESULTS.md, "Cost of accuracy").
/// The stage itself, timed directly (the default study, back to back, three runs each): radiance
/// 1.21–1.23 s in single against 1.33–1.34 s in double precision; the metrics move by about one
/// part in 10⁷. The gain is small (0.1 s of the study's 6 s, about 2 %) and the error nil at
/// the precision of any metric.
pub const DEFAULT_WATER_SINGLE_PRECISION: bool = true;

impl Fidelity {
    /// Every approximation off: the defaults, with per-pixel spectra on the full grid in double
    /// precision. The reference of the cost table (each setting's error is measured against it).
    #[must_use]
    pub fn full() -> Self {
        Self { band_nodes: 0, water_single_precision: false, ..Self::default() }
    }

    /// Check every number against [`crate::ranges`]; the message names field, value and range.
    pub fn validate(&self) -> Result<(), InstrumentError> {
        use crate::ranges as r;
        let check = |range: &r::Range, v: f64| {
            range.check(v).map_err(|message| InstrumentError::Invalid(FieldError { field: range.path.into(), message }))
        };
        check(&r::FIDELITY_SPECTRAL_STEP_NM, self.spectral_step_nm)?;
        check(&r::FIDELITY_SPATIAL_SAMPLES_PER_GSD, self.spatial_samples_per_gsd as f64)?;
        check(&r::FIDELITY_BAND_NODES, self.band_nodes as f64)?;
        check(&r::FIDELITY_DECIMATION, self.decimation as f64)?;
        check(&r::FIDELITY_LUT_WAVELENGTH_STEP_NM, self.lut_wavelength_step_nm)?;
        check(&r::FIDELITY_LUT_VIEW_STEP_DEG, self.lut_view_step_deg)?;
        check(&r::FIDELITY_SNR_FRAMES, self.snr_frames as f64)?;
        check(&r::FIDELITY_SNR_DETECTORS, self.snr_detectors as f64)
    }
}

/// One run: a scene, an instrument, and every setting of the chain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// The file format's version ([`crate::schema`]); always the current one once read.
    #[serde(default = "crate::schema::current")]
    pub schema_version: u32,
    /// The scene.
    pub scene: SceneSpec,
    /// Directory relative paths in the scene are taken from (the scene file's).
    #[serde(default)]
    pub scene_dir: Option<PathBuf>,
    /// The instrument.
    pub instrument: InstrumentSpec,
    /// Noise and quantisation switches.
    #[serde(default)]
    pub detector: DetectorMode,
    /// Calibration settings and injected errors.
    #[serde(default)]
    pub calibration: CalibrationSpec,
    /// Atmospheric correction settings.
    #[serde(default)]
    pub correction: CorrectionSpec,
    /// Retrievals to run on the Rrs (none: the chain stops at Rrs).
    #[serde(default)]
    pub retrievals: Vec<RetrievalSpec>,
    /// Fidelity settings.
    #[serde(default)]
    pub fidelity: Fidelity,
    /// The radiance the SNR is stated at, W m⁻² sr⁻¹ µm⁻¹, as a spectrum sampled at each band
    /// centre (a mission's or IOCCG's "typical radiance": `Constant(40.0)`, or
    /// `Table(wavelength_nm: […], values: […])`); `None`: the scene's median water radiance.
    #[serde(default)]
    pub snr_reference: Option<crate::spectral::SpectrumSource>,
    /// Seed of every random draw of the instrument (noise, fixed patterns, calibration frames,
    /// the approximation's sample points). The scene's maps have their own seeds.
    #[serde(default)]
    pub seed: u64,
    /// A fault to inject (tests of the failure path; never written to or read from files).
    #[serde(skip)]
    pub fault: Option<super::Fault>,
}

impl RunConfig {
    /// The configuration as flown: the instrument with on-board binning folded into its pixels
    /// ([`InstrumentSpec::as_flown`]), what the engine simulates; itself when nothing is binned.
    #[must_use]
    pub fn flown(&self) -> std::borrow::Cow<'_, Self> {
        match self.instrument.as_flown() {
            std::borrow::Cow::Borrowed(_) => std::borrow::Cow::Borrowed(self),
            std::borrow::Cow::Owned(instrument) => std::borrow::Cow::Owned(Self { instrument, ..self.clone() }),
        }
    }

    /// A run of `instrument` over `scene` with default settings.
    #[must_use]
    pub fn new(scene: SceneSpec, instrument: InstrumentSpec) -> Self {
        Self {
            schema_version: crate::schema::VERSION,
            scene,
            scene_dir: None,
            instrument,
            detector: DetectorMode::default(),
            calibration: CalibrationSpec::default(),
            correction: CorrectionSpec::default(),
            retrievals: Vec::new(),
            fidelity: Fidelity::default(),
            snr_reference: None,
            seed: 1,
            fault: None,
        }
    }

    /// Check every setting that needs no built stage against [`crate::ranges`] — instrument,
    /// fidelity, calibration, correction, the scene's numbers and atmosphere, the retrievals'
    /// settings — and what the run will ask of the machine against its budget
    /// ([`super::resources`]), so a bad value or a run that would not fit is refused before any
    /// stage runs, named with the stage that owns it. (The maps' values are checked when the
    /// scene stage builds them.)
    pub fn validate(&self) -> Result<(), super::EngineError> {
        self.validate_keeping(true)
    }

    /// [`Self::validate`] for an engine that keeps its cubes (`keep_cubes`) or a lean one
    /// ([`super::Engine::lean`]), whose run is planned at what it holds.
    pub fn validate_keeping(&self, keep_cubes: bool) -> Result<(), super::EngineError> {
        use super::{EngineError, Stage};
        fn at<E: std::fmt::Display>(stage: Stage) -> impl Fn(E) -> EngineError {
            move |e| EngineError::Failed { stage, message: e.to_string() }
        }
        self.instrument.validate().map_err(at(Stage::Response))?;
        self.fidelity.validate().map_err(at(Stage::Response))?;
        self.calibration.validate().map_err(at(Stage::Calibration))?;
        self.correction.validate().map_err(at(Stage::Correction))?;
        self.scene.validate().map_err(at(Stage::Scene))?;
        let mut atmosphere = self.scene.atmosphere.clone();
        atmosphere.day_of_year = crate::scene::day_of_year(&self.scene.date).map_err(at(Stage::Scene))?;
        atmosphere.validate().map_err(|e| at(Stage::Scene)(format!("atmosphere: {e}")))?;
        for (i, r) in self.retrievals.iter().enumerate() {
            r.validate().map_err(|e| at(Stage::Retrieval)(format!("{}: {e}", r.name())))?;
            // An external retrieval's name names its files and NetCDF variables: two of one name
            // would overwrite each other.
            let external = matches!(r, crate::retrieval::RetrievalSpec::External(_));
            if external && self.retrievals[..i].iter().any(|o| o.name() == r.name()) {
                return Err(at(Stage::Retrieval)(format!(
                    "retrievals[{i}].External.name: `{}` is taken by an earlier retrieval; give each its own name",
                    r.name()
                )));
            }
        }
        // What the run will ask of the machine, against its budget (`engine::resources`).
        let budget = crate::budget::MachineBudget::from_env().map_err(at(Stage::Scene))?;
        let demand = super::resources::run_demand_keeping(self, keep_cubes);
        budget.check(&demand).map_err(at(if demand.atmosphere_s > budget.atmosphere_s {
            Stage::Lut
        } else {
            Stage::Geometry
        }))?;
        Ok(())
    }

    /// Parse RON, brought up to date first ([`crate::schema::migrate`]); `origin` names the file
    /// in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, InstrumentError> {
        let parse = |message| InstrumentError::Parse(ParseError { origin: origin.into(), message });
        let text = crate::schema::migrate(text).map_err(parse)?;
        let mut config: Self = ron::from_str(&text).map_err(|e| parse(crate::parse::describe(&text, &e)))?;
        config.schema_version = crate::schema::VERSION;
        Ok(config)
    }

    /// Pretty RON (the resolved configuration written beside outputs).
    pub fn to_ron(&self) -> Result<String, InstrumentError> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default().struct_names(true))
            .map_err(|e| InstrumentError::Invalid(FieldError { field: "config".into(), message: e.to_string() }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fidelity_written_before_band_nodes_reads_the_full_grid() {
        // A resolved configuration from before the field: its results reproduce (0 = full grid).
        let old: Fidelity = ron::from_str("(spectral_step_nm: 1.0, decimation: 2)").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(old.band_nodes, 0);
        assert!(!old.water_single_precision, "written before the kernel's precision was a default");
        assert_eq!(old.decimation, 2);
        // No fidelity at all: the defaults, band nodes and the kernel's precision included.
        assert_eq!(Fidelity::default().band_nodes, DEFAULT_BAND_NODES);
        assert_eq!(Fidelity::default().water_single_precision, DEFAULT_WATER_SINGLE_PRECISION);
        assert_eq!(Fidelity::full(), Fidelity { band_nodes: 0, water_single_precision: false, ..Fidelity::default() });
    }

    #[test]
    fn a_configuration_written_before_the_schema_version_reads_as_today() {
        let scene = crate::scene::SceneSpec::preset("lake_hume_bloom").unwrap_or_else(|e| panic!("{e}"));
        let instrument = crate::instrument::InstrumentSpec::preset("cubesat").unwrap_or_else(|e| panic!("{e}"));
        let today = RunConfig::new(scene, instrument);
        let text = today.to_ron().unwrap_or_else(|e| panic!("{e}"));
        let version = format!("schema_version: {}", crate::schema::VERSION);
        assert!(text.contains(&version), "written with its version");
        // As an older Shoal wrote it: no version, the instrument's `lines` called `exposures`.
        let old = text.replace(&format!("    {version},\n"), "").replace("lines: 2000", "exposures: 2000");
        assert!(!old.contains("schema_version") && old.contains("exposures: 2000"));
        assert_eq!(RunConfig::from_ron(&old, "old.ron").unwrap_or_else(|e| panic!("{e}")), today);
        let newer = text.replace(&version, &format!("schema_version: {}", crate::schema::VERSION + 1));
        let e = RunConfig::from_ron(&newer, "new.ron").unwrap_err().to_string();
        assert!(e.contains("new.ron") && e.contains("newer Shoal"), "{e}");
    }
}

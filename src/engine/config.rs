//! A run's configuration: everything that decides its result, serialisable as the "fully
//! resolved configuration" written beside every output.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::calibration::CalibrationSpec;
use crate::correction::CorrectionSpec;
use crate::instrument::{DetectorMode, InstrumentError, InstrumentSpec};
use crate::retrieval::RetrievalSpec;
use crate::scene::SceneSpec;

/// Fidelity settings: what accuracy is bought with time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Fidelity {
    /// Spectral step of the simulation grids, nm (0.1–10).
    pub spectral_step_nm: f64,
    /// Spatial-response quadrature points per GSD along each axis (1–8), when the scene asks for
    /// `SpatialResponse`.
    pub spatial_samples_per_gsd: usize,
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
            decimation: 1,
            lut_wavelength_step_nm: 20.0,
            lut_view_step_deg: 5.0,
            snr_frames: 128,
            snr_detectors: 256,
        }
    }
}

impl Fidelity {
    /// Check every number; the message names the field and the range.
    pub fn validate(&self) -> Result<(), InstrumentError> {
        let bad = |field: &str, message: String| {
            Err(InstrumentError::Invalid { field: format!("fidelity.{field}"), message })
        };
        if !(self.spectral_step_nm.is_finite() && (0.1..=10.0).contains(&self.spectral_step_nm)) {
            return bad(
                "spectral_step_nm",
                format!("{} is out of range (allowed: 0.1 to 10 nm)", self.spectral_step_nm),
            );
        }
        if !(1..=8).contains(&self.spatial_samples_per_gsd) {
            return bad(
                "spatial_samples_per_gsd",
                format!("{} is out of range (allowed: 1 to 8)", self.spatial_samples_per_gsd),
            );
        }
        if !(1..=1000).contains(&self.decimation) {
            return bad("decimation", format!("{} is out of range (allowed: 1 to 1000)", self.decimation));
        }
        if !(self.lut_wavelength_step_nm.is_finite() && (5.0..=50.0).contains(&self.lut_wavelength_step_nm)) {
            return bad(
                "lut_wavelength_step_nm",
                format!("{} is out of range (allowed: 5 to 50 nm)", self.lut_wavelength_step_nm),
            );
        }
        if !(self.lut_view_step_deg.is_finite() && (1.0..=20.0).contains(&self.lut_view_step_deg)) {
            return bad(
                "lut_view_step_deg",
                format!("{} is out of range (allowed: 1 to 20 degrees)", self.lut_view_step_deg),
            );
        }
        if !(2..=10_000).contains(&self.snr_frames) {
            return bad("snr_frames", format!("{} is out of range (allowed: 2 to 10000)", self.snr_frames));
        }
        if !(1..=20_000).contains(&self.snr_detectors) {
            return bad("snr_detectors", format!("{} is out of range (allowed: 1 to 20000)", self.snr_detectors));
        }
        Ok(())
    }
}

/// One run: a scene, an instrument, and every setting of the chain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
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
    /// Seed of every random draw of the instrument (noise, fixed patterns, calibration frames,
    /// the approximation's sample points). The scene's maps have their own seeds.
    #[serde(default)]
    pub seed: u64,
    /// A fault to inject (tests of the failure path; never written to or read from files).
    #[serde(skip)]
    pub fault: Option<super::Fault>,
}

impl RunConfig {
    /// A run of `instrument` over `scene` with default settings.
    #[must_use]
    pub fn new(scene: SceneSpec, instrument: InstrumentSpec) -> Self {
        Self {
            scene,
            scene_dir: None,
            instrument,
            detector: DetectorMode::default(),
            calibration: CalibrationSpec::default(),
            correction: CorrectionSpec::default(),
            retrievals: Vec::new(),
            fidelity: Fidelity::default(),
            seed: 1,
            fault: None,
        }
    }

    /// Parse RON; `origin` names the file in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, InstrumentError> {
        ron::from_str(text)
            .map_err(|e| InstrumentError::Parse { origin: origin.into(), message: crate::parse::describe(text, &e) })
    }

    /// Pretty RON (the resolved configuration written beside outputs).
    pub fn to_ron(&self) -> Result<String, InstrumentError> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default().struct_names(true))
            .map_err(|e| InstrumentError::Invalid { field: "config".into(), message: e.to_string() })
    }
}

//! Instruments: how a satellite imager turns the scene's top-of-atmosphere radiance into
//! Level-0 counts.
//!
//! | part | module | what it models |
//! |---|---|---|
//! | the file | [`spec`] | every Table 1 parameter of Matthews et al. (2023) and the model kind |
//! | focal planes | [`focal`] | detectors beyond the first (SWIR InGaAs, MCT), pitch, dark-current temperature laws |
//! | spectral response | [`response`] | SRF × QE × photon weighting per band, smile, keystone |
//! | viewing geometry | [`geometry`] | pushbroom ground points, view zenith and azimuth, spherical Earth |
//! | spatial response | [`spatial`] | diffraction, detector footprint, along-track smear (when asked) |
//! | sampling | [`sample`] | band radiance of every pixel from the scene, and its truth |
//! | aerosol map | [`aerosol_map`] | the atmosphere pixel by pixel where the scene's AOT varies |
//! | effects | [`effects`] | stray light, polarisation sensitivity: the optics between pupil and detector |
//! | detector | [`detector`] | photo-electrons, shot/dark/read noise, PRNU/DSNU, full well, ADC |
//! | Level-0 | [`level0`] | the whole image exposed and read out, with flags |
//! | compression | [`compression`] | the on-board coder: its rate and the error it leaves in the counts |
//! | plausibility | [`plausibility`] | saturation at the brightest water, smear, f-number warnings |
//! | truth | [`truth`] | the scene's values under every pixel, scored against by the metrics |
//! | truth shares | [`shares`] | depth bins and substrate shares of the water pixels seen |
//! | SNR | [`snr`] | analytic SNR and SNR measured on a simulated uniform patch |
//! | budgets | [`budgets`] | cost, envelope and form factor, mass and power, data rate and volume |
//!
//! Four kinds (see [`InstrumentKind`]): a band-pass multispectral imager, an ideal radiometer
//! for reference runs, a long-slit dispersive spectrograph (CHICO-like) and a gradient /
//! linear-variable-filter imager (CyanoSat-like).
//!
//! ## References
//! - Matthews, M. W. et al. (2023) Demonstration of a modular prototype end-to-end simulator for
//!   aquatic remote sensing applications. Sensors 23, 7824 (§2.1.2, Table 1, Appendix A).
//! - Janesick, J. R. (2007) Photon Transfer: DN → λ. SPIE Press, Bellingham (noise model,
//!   photon transfer, quantisation noise gain²/12).
//! - Schowengerdt, R. A. (2007) Remote Sensing: Models and Methods for Image Processing, 3rd ed.,
//!   Academic Press, ch. 3 (pushbroom geometry, system PSF = optics ⊗ detector ⊗ motion).

pub mod aerosol_map;
pub mod band_atmosphere;
pub mod budgets;
pub mod compression;
pub mod detector;
pub mod effects;
pub mod feasibility;
pub mod focal;
pub mod geometry;
pub mod kind;
pub mod level0;
pub mod plausibility;
pub mod response;
pub mod sample;
pub mod shares;
pub mod snr;
pub mod spatial;
pub mod spec;
pub mod truth;

pub use detector::{Detector, DetectorMode, Flags};
pub use effects::InstrumentEffect;
pub use focal::{BandSelection, DarkLaw, DarkTemperature, DetectorMaterial, FocalPlane, Sampling};
pub use geometry::{LineOfSight, Look, Viewing, line_of_sight};
pub use level0::{Level0, digitise_cube, expose_and_digitise, expose_cube};
pub use response::{GeometryGroup, Response};
pub use sample::{AotNodes, BandAtmosphere, RadianceCube, SampleOptions, sample_radiance};
pub use snr::{SnrRow, analytic_snr, measured_snr};
pub use spatial::SpatialKernel;
pub use spec::{InstrumentKind, InstrumentSpec, ground_speed_m_s};
pub use truth::{SurfaceClass, SurfaceMap, Truth};

use crate::parse::{FieldError, ParseError};
use crate::scene::SceneError;
use crate::spectral::SpectralError;

/// Errors from the instrument stage; each names the field and what is allowed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum InstrumentError {
    /// A field with an invalid value.
    #[error(transparent)]
    Invalid(#[from] FieldError),
    /// A file that does not parse.
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// From the spectral layer (bands, QE curve).
    #[error(transparent)]
    Spectral(#[from] SpectralError),
    /// From the scene while sampling it.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The run was cancelled (a newer request superseded it).
    #[error("cancelled")]
    Cancelled,
}

impl crate::control::Cancellable for InstrumentError {
    fn cancelled() -> Self {
        Self::Cancelled
    }

    fn is_cancelled(&self) -> bool {
        matches!(self, Self::Cancelled)
    }
}

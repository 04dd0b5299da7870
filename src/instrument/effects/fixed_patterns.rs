//! Fixed patterns the on-board calibration does not remove: striping and defective pixels.
//!
//! The detector's own photo-response and dark-signal non-uniformity (PRNU, DSNU: fields of the
//! instrument) are measured by the diffuser and dark frames and removed with them. What is left
//! in the scene is what changed since, or what the frames cannot see:
//!
//! - **striping**: each detector's gain and dark signal drift between calibration and the scene
//!   by a relative rms `gain_drift` and an rms `offset_drift_e` (Level-1 is then striped along
//!   track; residual non-uniformity of this size is what pushbroom missions report after
//!   on-board calibration, Gascon et al. 2017, §2.2);
//! - **dead pixels**: a share `dead_fraction` of detector elements has no response. The
//!   calibration finds them (their gain below a tenth of the band's median) and either flags
//!   them, so that no product is made from them, or replaces each by the mean of its nearest
//!   working neighbours across track (`interpolate_dead`: the way Sentinel-2's Level-1 fills
//!   its defective pixels);
//! - **hot pixels**: a share `hot_fraction` collects `hot_dark_current_e_s` more dark current.
//!   Dark frames of zero length (the paper's) do not see it; dark frames as long as the scene's
//!   (`calibration.dark_exposure_s`) remove it.
//!
//! Crosstalk between neighbouring detectors is part of the spatial response (the MTF budget's
//! `crosstalk`, [`super::MtfBudget`]).
//!
//! Every detector element's draws come from its own generator (run seed, detector, band), so
//! the pattern does not depend on threads or on the preview's decimation.
//!
//! ## References
//! - Gascon, F. et al. (2017) Copernicus Sentinel-2A calibration and products validation
//!   status. Remote Sens. 9, 584.

use serde::{Deserialize, Serialize};

use super::{Effect, InstrumentError, check};
use crate::ranges as r;

/// Fixed patterns as an instrument file states them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FixedPatterns {
    /// Relative rms drift of each detector element's gain since calibration (0.002: 0.2 %).
    pub gain_drift: f64,
    /// Rms drift of each detector element's dark signal since calibration, e⁻.
    pub offset_drift_e: f64,
    /// Share of detector elements with no response.
    pub dead_fraction: f64,
    /// Share of detector elements with extra dark current.
    pub hot_fraction: f64,
    /// Extra dark current of a hot element, e⁻ s⁻¹.
    pub hot_dark_current_e_s: f64,
    /// The processor fills dead elements from their neighbours (else it flags them).
    pub interpolate_dead: bool,
}

impl Default for FixedPatterns {
    fn default() -> Self {
        Self {
            gain_drift: 0.0,
            offset_drift_e: 0.0,
            dead_fraction: 0.0,
            hot_fraction: 0.0,
            hot_dark_current_e_s: 0.0,
            interpolate_dead: true,
        }
    }
}

impl Effect for FixedPatterns {
    fn name(&self) -> &'static str {
        "FixedPatterns"
    }

    fn role(&self) -> super::Role {
        super::Role::Detector
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::PATTERN_GAIN_DRIFT, self.gain_drift, &format!("{at}.gain_drift"))?;
        check(&r::PATTERN_OFFSET_DRIFT_E, self.offset_drift_e, &format!("{at}.offset_drift_e"))?;
        check(&r::PATTERN_DEAD_FRACTION, self.dead_fraction, &format!("{at}.dead_fraction"))?;
        check(&r::PATTERN_HOT_FRACTION, self.hot_fraction, &format!("{at}.hot_fraction"))?;
        check(&r::PATTERN_HOT_DARK_E_S, self.hot_dark_current_e_s, &format!("{at}.hot_dark_current_e_s"))
    }

    fn on_the_cube(&self) -> bool {
        false
    }
}

//! On-board compression of Level-0 as an instrument file states it; the coder itself is
//! [`crate::instrument::compression`] (it acts on the counts, after the detector).

use serde::{Deserialize, Serialize};

use super::{Effect, InstrumentError, check};
use crate::ranges as r;

/// Compression as an instrument file states it: near-lossless with an error bound, optionally
/// held to a rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Compression {
    /// Largest reconstruction error, DN (0: lossless).
    pub max_error_dn: u32,
    /// Bits per sample the downlink allows (0: no rate target). The coder then takes the
    /// smallest error bound, at least `max_error_dn`, whose rate meets it.
    pub bits_per_sample: f64,
}

impl Default for Compression {
    fn default() -> Self {
        Self { max_error_dn: 0, bits_per_sample: 0.0 }
    }
}

impl Effect for Compression {
    fn name(&self) -> &'static str {
        "Compression"
    }

    fn role(&self) -> super::Role {
        super::Role::FocalPlane
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::COMPRESSION_MAX_ERROR_DN, f64::from(self.max_error_dn), &format!("{at}.max_error_dn"))?;
        check(&r::COMPRESSION_BITS_PER_SAMPLE, self.bits_per_sample, &format!("{at}.bits_per_sample"))
    }

    fn on_the_cube(&self) -> bool {
        false
    }
}

//! A real spacecraft's orbit from its two-line elements (TLE), propagated with SGP4 — the
//! propagator the elements are fitted for (Hoots & Roehrich 1980, Spacetrack Report #3, as
//! revised by Vallado et al. 2006) — through the `sgp4` crate in its AFSPC-compatible mode (the
//! WGS-72 constants and epoch convention the element sets are made with; it reproduces Vallado's
//! published verification vectors to 1e-8 km, `tests.rs`).
//!
//! SGP4 gives the position in the TEME frame (true equator, mean equinox of date). The
//! Earth-fixed position is TEME rotated about the pole by Greenwich mean sidereal time
//! (Vallado et al. 2006, §"TEME": PEF = R₃(GMST)·TEME; polar motion, below 15 m, is left out, as
//! is the difference between the sidereal-time expressions, below a microradian).
//!
//! ## References
//! - Hoots, F. R. & Roehrich, R. L. (1980) *Spacetrack Report #3: Models for Propagation of
//!   NORAD Element Sets*, Aerospace Defense Command.
//! - Vallado, D. A., Crawford, P., Hujsak, R. & Kelso, T. S. (2006) Revisiting Spacetrack Report
//!   #3, AIAA 2006-6753.

use super::Track;
use super::sun;

/// A spacecraft flying its two-line elements.
#[derive(Debug, Clone)]
pub struct TleOrbit {
    constants: sgp4::Constants,
    /// The elements' epoch, days since J2000.0.
    pub epoch_days: f64,
    /// Mean motion, rad/s (the elements' revolutions per day).
    mean_motion_rad_s: f64,
    /// The elements' eccentricity.
    eccentricity: f64,
}

impl TleOrbit {
    /// The orbit of the element set `line1`, `line2`.
    ///
    /// # Errors
    /// Lines that are not a TLE (format, checksum) or elements SGP4 cannot propagate, with the
    /// reason the parser gives.
    pub fn from_lines(line1: &str, line2: &str) -> Result<Self, String> {
        let elements = sgp4::Elements::from_tle(None, line1.trim().as_bytes(), line2.trim().as_bytes())
            .map_err(|e| e.to_string())?;
        let constants =
            sgp4::Constants::from_elements_afspc_compatibility_mode(&elements).map_err(|e| e.to_string())?;
        // Julian years of 365.25 days since J2000.0, as SGP4 counts them.
        let epoch_days = elements.epoch_afspc_compatibility_mode() * 365.25;
        Ok(Self {
            constants,
            epoch_days,
            mean_motion_rad_s: elements.mean_motion * std::f64::consts::TAU / sun::DAY_S,
            eccentricity: elements.eccentricity,
        })
    }

    /// Position in the TEME frame at `days` since J2000.0, m, or `None` where SGP4 stops (the
    /// orbit decayed).
    #[must_use]
    pub fn position_teme_m(&self, days: f64) -> Option<[f64; 3]> {
        let minutes = (days - self.epoch_days) * 1440.0;
        let p = self.constants.propagate(sgp4::MinutesSinceEpoch(minutes)).ok()?.position;
        Some([p[0] * 1e3, p[1] * 1e3, p[2] * 1e3])
    }

    /// Earth-fixed position at `days` since J2000.0, m (x to Greenwich on the equator, z north).
    #[must_use]
    pub fn position_ecef_m(&self, days: f64) -> Option<[f64; 3]> {
        let p = self.position_teme_m(days)?;
        let (sg, cg) = sun::gmst_rad(days).sin_cos();
        Some([p[0] * cg + p[1] * sg, -p[0] * sg + p[1] * cg, p[2]])
    }
}

impl Track for TleOrbit {
    fn at(&self, days: f64) -> Option<([f64; 3], f64)> {
        let p = self.position_ecef_m(days)?;
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        (r > 0.0).then(|| ([p[0] / r, p[1] / r, p[2] / r], r))
    }

    fn angular_rate_rad_s(&self) -> f64 {
        self.mean_motion_rad_s
    }

    /// The rate at perigee, n·(1 + e)²/(1 − e²)^{3/2} (Kepler's second law: r²·dν/dt =
    /// n·a²·√(1 − e²) at r = a(1 − e); Vallado 2013, §2.3), with e 0.02 above the elements' for
    /// SGP4's perturbations of it over the period.
    fn max_angular_rate_rad_s(&self) -> f64 {
        let e = (self.eccentricity + 0.02).min(0.95);
        self.mean_motion_rad_s * (1.0 + e).powi(2) / (1.0 - e * e).powf(1.5)
    }
}

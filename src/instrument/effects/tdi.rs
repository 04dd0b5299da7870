//! Time-delay integration: a pushbroom plane with N rows per band whose charge (or digitised
//! reads) moves with the image, so each ground line is integrated N times.
//!
//! | | charge-domain TDI (CCD) | digital TDI (CMOS, summed reads) |
//! |---|---|---|
//! | signal, dark signal | N × one row's | one row's, averaged over N reads |
//! | shot noise | √N × one row's | one row's / √N |
//! | read noise | one read, σ | N reads averaged, σ/√N |
//! | full well | the register's, W, for the sum | W per read |
//! | PRNU, DSNU (N pixels pooled) | PRNU/√N; DSNU·√N e⁻ | PRNU/√N; DSNU/√N |
//!
//! so the signal-to-noise ratio gains √N where shot noise dominates, and N (charge) or √N
//! (digital) where read noise does (Holst & Lomheim 2011, §9.4; Lepage, Bogaerts & Meynants
//! 2009). Two losses reach the MTF along track (applied through the MTF budget,
//! [`super::mtf`]):
//!
//! - a line rate off the image's motion by a fraction δ slips the image by |δ| pixels per stage:
//!   sinc(N·|δ|·g·ν) over the N stages (Holst & Lomheim 2011, §9.4; the smear formula of Fiete
//!   2010, eq. 4.40, over N·|δ| pixels);
//! - charge transfer inefficiency ε = 1 − CTE over the N transfers of charge-domain TDI:
//!   exp(−N·ε·(1 − cos 2πgν)) (Janesick 2001, §5.3; digital TDI moves no charge).
//!
//! A spectrograph's along-track axis is its spectrum (no TDI); a filter imager's stages fit
//! within a band's rows.
//!
//! ## References
//! - Holst, G. C., Lomheim, T. S. (2011) CMOS/CCD Sensors and Camera Systems, 2nd ed. SPIE /
//!   JCD, §9.4 (TDI).
//! - Lepage, G., Bogaerts, J., Meynants, G. (2009) Time-delay-integration architectures in CMOS
//!   image sensors. IEEE Trans. Electron Devices 56, 2524–2533.
//! - Janesick, J. R. (2001) Scientific Charge-Coupled Devices. SPIE Press, §5.3 (CTE and MTF).
//! - Fiete, R. D. (2010) Modeling the Imaging Chain of Digital Cameras. SPIE TT92.

use serde::{Deserialize, Serialize};

use super::{Effect, InstrumentError, check};
use crate::ranges as r;

/// Time-delay integration as an instrument file states it (every focal plane of the design).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Tdi {
    /// Rows integrated per band, N.
    pub stages: u32,
    /// Reads summed digitally (CMOS) rather than charge moved (CCD).
    pub digital: bool,
    /// Relative error of the line rate against the image's motion, δ.
    pub line_rate_error: f64,
    /// Charge transfer efficiency per stage (charge-domain TDI only).
    pub cte: f64,
}

impl Default for Tdi {
    fn default() -> Self {
        Self { stages: 1, digital: false, line_rate_error: 0.0, cte: 1.0 }
    }
}

impl Tdi {
    /// N as a number.
    #[must_use]
    pub fn n(&self) -> f64 {
        f64::from(self.stages.max(1))
    }

    /// Ground distance the image slips against the charge over the N stages, for a ground
    /// pitch `pitch_m`.
    #[must_use]
    pub fn slip_m(&self, pitch_m: f64) -> f64 {
        self.n() * self.line_rate_error.abs() * pitch_m
    }

    /// N·ε, the charge lost to transfers (0 for digital TDI).
    #[must_use]
    pub fn transfer_loss(&self) -> f64 {
        if self.digital { 0.0 } else { self.n() * (1.0 - self.cte) }
    }
}

impl Effect for Tdi {
    fn name(&self) -> &'static str {
        "Tdi"
    }

    fn role(&self) -> super::Role {
        super::Role::Detector
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::TDI_STAGES, f64::from(self.stages), &format!("{at}.stages"))?;
        check(&r::TDI_LINE_RATE_ERROR, self.line_rate_error, &format!("{at}.line_rate_error"))?;
        check(&r::TDI_CTE, self.cte, &format!("{at}.cte"))
    }

    fn on_the_cube(&self) -> bool {
        false
    }
}

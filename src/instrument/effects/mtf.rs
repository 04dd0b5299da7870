//! The MTF budget: the system's modulation transfer function as the product of its parts, and
//! the point-spread function the image is sampled with.
//!
//! A linear, shift-invariant imaging chain multiplies the transfer functions of its parts
//! (Fiete 2010, ch. 4; Holst 2008; Schowengerdt 2007, §3.4). On the ground, at spatial
//! frequency ν (cycles m⁻¹) along an axis, for a band at λ:
//!
//! | part | transfer function | source |
//! |---|---|---|
//! | diffraction, aperture D with central obstruction ε | annular-pupil OTF at v = ν/ν_c, ν_c = D/(λH) | O'Neill 1956 |
//! | wavefront error W (RMS, waves = W_nm/λ) | 1 − (W/0.18)²·[1 − 4(v − ½)²] | Shannon 1997; Fiete 2010, eq. 4.29 |
//! | pixel aperture (fill φ of the ground pitch g) | sinc(φ g ν) | Fiete 2010, eq. 4.36 |
//! | charge diffusion, σ_d in the focal plane | exp(−2π² (σ_d H/f)² ν²) | Fiete 2010, §4.4 (Gaussian) |
//! | crosstalk, a share c to each neighbour | 1 − 2c·(1 − cos 2π g ν) | kernel [c, 1 − 2c, c] |
//! | line-of-sight jitter, σ_j rad RMS | exp(−2π² (σ_j H)² ν²) | Fiete 2010, eq. 4.45 |
//! | smear over the exposure (along track) | sinc(v t ν) | Fiete 2010, eq. 4.40 |
//! | TDI line-rate mismatch (along track) | sinc(N·|δ|·g·ν) | [`super::tdi`] |
//! | TDI charge transfer (along track) | exp(−N·ε·(1 − cos 2πgν)) | Janesick 2001, §5.3 |
//!
//! with sinc(x) = sin(πx)/(πx). H is the altitude, f the focal length, v the ground speed, t
//! the exposure: the geometry is nadir's. Shannon's aberration factor is an empirical fit good to
//! W ≈ 0.18 waves; beyond, it is held at zero rather than let negative.
//!
//! The figure reviews state is the MTF at Nyquist, ν_N = 1/(2g) (Sentinel-2 MSI specifies
//! 0.15–0.30 for its 10 m bands: Drusch et al. 2012).
//!
//! ## The PSF the image is sampled with
//! Along each axis the line-spread function is the inverse transform of the (real, even) OTF
//! along that axis, and the share of a sub-cell of width h centred at x_k = k·h is
//! w_k = ∫₀^{ν_c} 2·OTF(ν)·h·sinc(νh)·cos(2πνx_k) dν (diffraction cuts the OTF off at ν_c, so
//! the integral is finite; Simpson's rule). The 2-D weight is the product of the two axes'
//! weights: a separable PSF whose transfer function along either axis is the budget's exactly
//! (a circular pupil's PSF is not separable, but its OTF on the axes is what a slanted-edge
//! measurement along or across track reports).
//!
//! ## References
//! - Fiete, R. D. (2010) Modeling the Imaging Chain of Digital Cameras. SPIE Tutorial Texts
//!   TT92, ch. 4.
//! - Holst, G. C. (2008) Electro-Optical Imaging System Performance, 5th ed. SPIE / JCD.
//! - O'Neill, E. L. (1956) Transfer function for an annular aperture. J. Opt. Soc. Am. 46,
//!   285–288.
//! - Shannon, R. R. (1997) The Art and Science of Optical Design. Cambridge University Press.
//! - Schowengerdt, R. A. (2007) Remote Sensing: Models and Methods for Image Processing, 3rd ed.
//! - Drusch, M. et al. (2012) Sentinel-2: ESA's optical high-resolution mission for GMES
//!   operational services. Remote Sens. Environ. 120, 25–36.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::{InstrumentError, check};
use crate::ranges as r;

/// An instrument's MTF budget beyond the ideal optic (every field 0, fill 1: a diffraction-limited
/// unobstructed telescope, a full-fill pixel, smear, nothing else).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MtfBudget {
    /// Central obstruction: the secondary's diameter over the aperture's (0–0.8).
    pub obstruction: f64,
    /// RMS wavefront error of the telescope, nm (0–70; defocus included).
    pub wavefront_rms_nm: f64,
    /// Width of a pixel's sensitive aperture over its pitch (0.3–1).
    pub pixel_fill: f64,
    /// Charge diffusion: the Gaussian σ of the spread in the focal plane, µm (0–20).
    pub diffusion_um: f64,
    /// Crosstalk: the share of a pixel's signal that lands on each neighbour (0–0.2).
    pub crosstalk: f64,
    /// Line-of-sight jitter during an exposure, µrad RMS (0–100).
    pub jitter_urad: f64,
}

impl Default for MtfBudget {
    fn default() -> Self {
        Self {
            obstruction: 0.0,
            wavefront_rms_nm: 0.0,
            pixel_fill: 1.0,
            diffusion_um: 0.0,
            crosstalk: 0.0,
            jitter_urad: 0.0,
        }
    }
}

/// The direction a transfer function is taken in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Along track (the smear's direction).
    Along,
    /// Across track.
    Across,
}

/// The geometry a budget is evaluated in: one focal plane of one instrument, at nadir.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MtfGeometry {
    /// Aperture diameter, m.
    pub aperture_m: f64,
    /// Altitude, m.
    pub altitude_m: f64,
    /// Focal length, m.
    pub focal_length_m: f64,
    /// The plane's pixel pitch on the ground, m.
    pub pitch_ground_m: f64,
    /// Ground distance moved during one exposure, m.
    pub smear_m: f64,
    /// Ground distance the image slips against TDI's charge over its stages, m (0 without TDI).
    pub tdi_slip_m: f64,
    /// N·(1 − CTE) of charge-domain TDI (0 without).
    pub tdi_transfer_loss: f64,
}

impl MtfGeometry {
    /// Ground Nyquist frequency of the plane, cycles m⁻¹.
    #[must_use]
    pub fn nyquist_per_m(&self) -> f64 {
        0.5 / self.pitch_ground_m
    }

    /// Diffraction cut-off on the ground at `wavelength_nm`, cycles m⁻¹ (D/(λH)).
    #[must_use]
    pub fn cutoff_per_m(&self, wavelength_nm: f64) -> f64 {
        self.aperture_m / (wavelength_nm * 1e-9 * self.altitude_m)
    }
}

/// sin(πx)/(πx).
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-9 { 1.0 } else { (PI * x).sin() / (PI * x) }
}

/// The diffraction OTF of an annular pupil of obstruction `eps` at `v` = ν/ν_c (O'Neill 1956).
#[must_use]
pub fn annular_otf(v: f64, eps: f64) -> f64 {
    if v >= 1.0 {
        return 0.0;
    }
    let v = v.max(0.0);
    let lens = |x: f64| (2.0 / PI) * (x.acos() - x * (1.0 - x * x).sqrt());
    let a = lens(v);
    if eps <= 0.0 {
        return a;
    }
    let e2 = eps * eps;
    let b = if v <= eps { e2 * lens(v / eps) } else { 0.0 };
    let c = if v <= 0.5 * (1.0 - eps) {
        -2.0 * e2
    } else if v < 0.5 * (1.0 + eps) {
        let phi = ((1.0 + e2 - 4.0 * v * v) / (2.0 * eps)).clamp(-1.0, 1.0).acos();
        (2.0 * eps / PI) * phi.sin() + ((1.0 + e2) / PI) * phi
            - (2.0 * (1.0 - e2) / PI) * (((1.0 + eps) / (1.0 - eps)) * (0.5 * phi).tan()).atan()
            - 2.0 * e2
    } else {
        0.0
    };
    ((a + b + c) / (1.0 - e2)).max(0.0)
}

/// One part of the budget at one frequency: its name and its transfer function (signed: a
/// sinc's negative lobes are a contrast reversal).
pub type Part = (&'static str, f64);

impl MtfBudget {
    /// Check the fields (`at` names the entry).
    pub fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::MTF_OBSTRUCTION, self.obstruction, &format!("{at}.obstruction"))?;
        check(&r::MTF_WAVEFRONT_RMS_NM, self.wavefront_rms_nm, &format!("{at}.wavefront_rms_nm"))?;
        check(&r::MTF_PIXEL_FILL, self.pixel_fill, &format!("{at}.pixel_fill"))?;
        check(&r::MTF_DIFFUSION_UM, self.diffusion_um, &format!("{at}.diffusion_um"))?;
        check(&r::MTF_CROSSTALK, self.crosstalk, &format!("{at}.crosstalk"))?;
        check(&r::MTF_JITTER_URAD, self.jitter_urad, &format!("{at}.jitter_urad"))
    }

    /// Each part's transfer function at ground frequency `nu_per_m` along `axis`, for a band at
    /// `wavelength_nm` (the table in the module's documentation).
    #[must_use]
    pub fn parts(&self, g: &MtfGeometry, wavelength_nm: f64, nu_per_m: f64, axis: Axis) -> [Part; 9] {
        let v = nu_per_m / g.cutoff_per_m(wavelength_nm);
        let waves = self.wavefront_rms_nm / wavelength_nm;
        let aberration =
            if v >= 1.0 { 1.0 } else { (1.0 - (waves / 0.18).powi(2) * (1.0 - 4.0 * (v - 0.5).powi(2))).max(0.0) };
        let gauss = |sigma_m: f64| (-2.0 * PI * PI * sigma_m * sigma_m * nu_per_m * nu_per_m).exp();
        let scale = g.altitude_m / g.focal_length_m;
        let along = |f: f64| if axis == Axis::Along { f } else { 1.0 };
        let smear = along(sinc(g.smear_m * nu_per_m));
        let slip = along(sinc(g.tdi_slip_m * nu_per_m));
        let transfer = along((-g.tdi_transfer_loss * (1.0 - (2.0 * PI * g.pitch_ground_m * nu_per_m).cos())).exp());
        [
            ("diffraction", annular_otf(v, self.obstruction)),
            ("wavefront error", aberration),
            ("pixel aperture", sinc(self.pixel_fill * g.pitch_ground_m * nu_per_m)),
            ("charge diffusion", gauss(self.diffusion_um * 1e-6 * scale)),
            ("crosstalk", 1.0 - 2.0 * self.crosstalk * (1.0 - (2.0 * PI * g.pitch_ground_m * nu_per_m).cos())),
            ("jitter", gauss(self.jitter_urad * 1e-6 * g.altitude_m)),
            ("smear", smear),
            ("TDI line rate", slip),
            ("TDI transfer", transfer),
        ]
    }

    /// The system's transfer function (the product of the parts, signed).
    #[must_use]
    pub fn otf(&self, g: &MtfGeometry, wavelength_nm: f64, nu_per_m: f64, axis: Axis) -> f64 {
        self.parts(g, wavelength_nm, nu_per_m, axis).iter().map(|p| p.1).product()
    }

    /// The system MTF at the plane's Nyquist frequency.
    #[must_use]
    pub fn at_nyquist(&self, g: &MtfGeometry, wavelength_nm: f64, axis: Axis) -> f64 {
        self.otf(g, wavelength_nm, g.nyquist_per_m(), axis).abs()
    }

    /// The share of the line-spread function along `axis` in sub-cells of width `h_m` centred on
    /// 0, ±h, …, ±`k_max`·h (the module's integral by Simpson's rule; not normalised).
    #[must_use]
    pub fn cell_weights(&self, g: &MtfGeometry, wavelength_nm: f64, axis: Axis, h_m: f64, k_max: usize) -> Vec<f64> {
        let nu_c = g.cutoff_per_m(wavelength_nm);
        let span_m = (2 * k_max + 1) as f64 * h_m;
        // Resolve the fastest oscillation, cos(2πν·k_max·h), with 16 points per period.
        let n = ((nu_c * span_m * 16.0).ceil() as usize).clamp(256, 1 << 17) & !1;
        let step = nu_c / n as f64;
        let integrand: Vec<f64> = (0..=n)
            .map(|i| {
                let nu = i as f64 * step;
                let simpson = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                simpson * 2.0 * self.otf(g, wavelength_nm, nu, axis) * h_m * sinc(nu * h_m)
            })
            .collect();
        (0..=2 * k_max)
            .map(|c| {
                let x = (c as f64 - k_max as f64) * h_m;
                let sum: f64 =
                    integrand.iter().enumerate().map(|(i, f)| f * (2.0 * PI * i as f64 * step * x).cos()).sum();
                (sum * step / 3.0).max(0.0)
            })
            .collect()
    }

    /// Half-width on the ground that holds all but the far tails of the PSF along `axis`, m.
    #[must_use]
    pub fn reach_m(&self, g: &MtfGeometry, wavelength_nm: f64, axis: Axis) -> f64 {
        let scale = g.altitude_m / g.focal_length_m;
        let airy_sigma = 0.42 * wavelength_nm * 1e-9 * g.altitude_m / g.aperture_m * (1.0 + self.obstruction);
        let aberration = self.wavefront_rms_nm / wavelength_nm / 0.18 * 4.0 * airy_sigma;
        let sigma = (airy_sigma.powi(2)
            + aberration.powi(2)
            + (self.diffusion_um * 1e-6 * scale).powi(2)
            + (self.jitter_urad * 1e-6 * g.altitude_m).powi(2))
        .sqrt();
        let smear = if axis == Axis::Along { 0.5 * (g.smear_m + g.tdi_slip_m) } else { 0.0 };
        // Crosstalk and TDI's lost charge reach the neighbours (N·ε of them a pixel further on).
        let neighbours = if self.crosstalk > 0.0 || g.tdi_transfer_loss > 0.0 { g.pitch_ground_m } else { 0.0 };
        let trail = if axis == Axis::Along { 4.0 * g.tdi_transfer_loss * g.pitch_ground_m } else { 0.0 };
        let crosstalk = neighbours + trail;
        0.5 * self.pixel_fill * g.pitch_ground_m + smear + crosstalk + 16.0 * sigma
    }
}

impl super::Effect for MtfBudget {
    fn name(&self) -> &'static str {
        "SpatialResponse"
    }

    fn role(&self) -> super::Role {
        super::Role::Optics
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        MtfBudget::validate(self, at)
    }

    fn on_the_cube(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests;

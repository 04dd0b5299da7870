//! The path radiance's Stokes Q and U per output column and band, in the instrument's frame:
//! what a polarisation-sensitive instrument reads on top of the intensity.
//!
//! Per column and band: the degree-of-polarisation ratios (Q/I, U/I) of the path at the band's
//! centre and the column's geometry ([`crate::toa::SceneOptics::path_polarisation`]), times the
//! band-effective path radiance ([`super::super::BandAtmosphere`]: gases, solar spectrum and
//! response included), turned from the view's meridian frame into the instrument's (reference
//! axis along track) by α = view azimuth − heading ([`crate::atmosphere::stokes::rotate`]). The
//! ratio is taken at the band centre: Rayleigh's degree of polarisation does not depend on
//! wavelength, and the mixing with aerosol changes it slowly across a band.

use std::f64::consts::PI;

use super::super::{BandAtmosphere, InstrumentError, Response, Viewing};
use crate::atmosphere::stokes;
use crate::parse::FieldError;
use crate::toa::SceneOptics;

/// Per column × band: the path's Q′ and U′, W m⁻² sr⁻¹ nm⁻¹.
#[derive(Debug, Clone, PartialEq)]
pub struct StokesColumns {
    n_bands: usize,
    q: Vec<f64>,
    u: Vec<f64>,
}

impl StokesColumns {
    /// From values per column × band (column-major in bands: `c * n_bands + b`).
    #[must_use]
    pub fn from_parts(n_bands: usize, q: Vec<f64>, u: Vec<f64>) -> Self {
        Self { n_bands, q, u }
    }

    /// (Q′, U′) of column `c`, band `b`.
    #[must_use]
    pub fn qu(&self, c: usize, b: usize) -> (f64, f64) {
        let i = c * self.n_bands + b;
        (self.q[i], self.u[i])
    }

    /// The path's Q′ and U′ for every column of `viewing` and band of `response`, the sun at
    /// `sun_azimuth_rad` and the ground track at `heading_rad` (both clockwise from north).
    pub fn build(
        optics: &[SceneOptics],
        viewing: &Viewing,
        response: &Response,
        band_atmosphere: &BandAtmosphere,
        sun_azimuth_rad: f64,
        heading_rad: f64,
    ) -> Result<Self, InstrumentError> {
        let nb = response.n_bands();
        let nc = viewing.columns();
        let centres = response.bands.centres_nm();
        let (mut q, mut u) = (vec![0.0; nc * nb], vec![0.0; nc * nb]);
        for (g, group) in response.groups.iter().enumerate() {
            for c in 0..nc {
                let look = &viewing.looks[g][c];
                // The signed relative azimuth: U is odd in it (the look's own is folded to 0–π).
                let signed = (look.view_azimuth_rad - sun_azimuth_rad + PI).rem_euclid(2.0 * PI) - PI;
                let alpha = look.view_azimuth_rad - heading_rad;
                for &b in &group.bands {
                    let ratios = optics[g]
                        .path_polarisation(&look.geometry, centres[b])
                        .map_err(|e| InstrumentError::Scene(e.into()))?;
                    let Some((qi, ui)) = ratios else {
                        return Err(InstrumentError::Invalid(FieldError {
                            field: "effects[].Polarisation".into(),
                            message:
                                "needs the atmosphere's Q and U: set scene.atmosphere.accuracy.polarization_correction \
                                      to true and max_orders above 1 (the vector radiative transfer)"
                                    .into(),
                        }));
                    };
                    let ui = if signed < 0.0 { -ui } else { ui };
                    let l_path = band_atmosphere.l_path[c * nb + b];
                    let (qp, up) = stokes::rotate(qi * l_path, ui * l_path, alpha);
                    q[c * nb + b] = qp;
                    u[c * nb + b] = up;
                }
            }
        }
        Ok(Self { n_bands: nb, q, u })
    }
}

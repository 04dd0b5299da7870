//! The scene's truth under every pixel: what the retrievals are scored against.
//!
//! The sampling stage ([`super::sample`]) evaluates the scene once per pixel and keeps, beside
//! the radiance the instrument sees, the values the scene holds there. They travel as one
//! [`Truth`], shared by reference (`Arc`) from the radiance cube to the metrics, the study
//! tables and figures and the app, so a study keeps the truth of each run without copying it.

use ndarray::{Array2, Array3};

/// The scene's truth at each pixel centre, (row, column) maps on the instrument's grid.
#[derive(Debug, Clone, Default)]
pub struct Truth {
    /// True band remote-sensing reflectance above the surface, Rrs(0+), sr⁻¹ (0 on land),
    /// (row, column, band), weighted by each band's response as the radiance is.
    /// (The water model's `rrs` is below the surface, rrs(0−).)
    pub rrs_above: Array3<f32>,
    /// Chlorophyll-a, mg m⁻³.
    pub chl_mg_m3: Array2<f32>,
    /// Non-algal particles, g m⁻³.
    pub nap_g_m3: Array2<f32>,
    /// CDOM absorption at 440 nm, m⁻¹.
    pub cdom_per_m: Array2<f32>,
    /// Depth, m (shallow scenes only).
    pub depth_m: Option<Array2<f32>>,
    /// Substrate fractions (row, column, substrate), normalised (shallow scenes only).
    pub substrate_fractions: Option<Array3<f32>>,
    /// Names of the substrates of `substrate_fractions`, in its order.
    pub substrate_names: Vec<String>,
    /// 1 where the pixel centre is land.
    pub land: Array2<u8>,
    /// Aerosol optical thickness at 550 nm at each pixel centre, where the scene gives it as a
    /// map (`aot550_map`; otherwise the atmosphere's `aot550` holds everywhere).
    pub aot550: Option<Array2<f32>>,
}

impl Truth {
    /// Whether pixel (row, column) is water.
    #[must_use]
    pub fn is_water(&self, row: usize, column: usize) -> bool {
        self.land[[row, column]] == 0
    }

    /// The truth map of a scalar product variable (`chl_mg_m3`, `nap_g_m3`, `cdom_per_m`,
    /// `depth_m`), if this truth has it.
    #[must_use]
    pub fn map(&self, variable: &str) -> Option<&Array2<f32>> {
        use crate::variable::key;
        match variable {
            key::CHL => Some(&self.chl_mg_m3),
            key::NAP => Some(&self.nap_g_m3),
            key::CDOM => Some(&self.cdom_per_m),
            key::DEPTH => self.depth_m.as_ref(),
            _ => None,
        }
    }
}

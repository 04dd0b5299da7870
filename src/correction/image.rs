//! The image-based correction: the aerosol from the instrument's own Level-1, as a real
//! processor finds it, knowing nothing of the scene's true atmosphere. Two fits share the
//! family ([`super::family`]) and the per-pixel inversion (`apply`): the band pair below
//! (`pair.rs`, with the NIR water iteration of [`super::nir_water`]) and dark-spectrum fitting
//! ([`super::dark`]).
//!
//! **Two-band model selection** (Gordon & Wang 1994; Ahmad et al. 2010, as NASA's l2gen runs
//! it; Wang & Shi 2007 with a SWIR pair). A family of aerosol models, each tabulated at a few
//! optical depths: for every model m and AOT(550) node τ_k, Shoal's own atmosphere (WMO Mie
//! optics, successive orders) gives the band-effective path radiance L_path(m, τ_k), (T_up·Ed)
//! and spherical albedo S of every column, through each band's response — the same radiative
//! transfer as the forward model, so the family is exact where the scene's aerosol is a member.
//! Per pixel, with A(λ) = L1(λ) − L_path(λ; τ = 0) the aerosol's part of the signal and the
//! water taken as black at the pair's bands (their Rrs left in A is the black-pixel error,
//! which the NIR iteration estimates and takes away):
//!
//! 1. for each model, τ_m such that A_m(λ_l; τ_m) = A(λ_l) at the long band (quadratic in the
//!    signal over the three nearest nodes; beyond the last node, the last segment extended;
//!    below zero, τ_m = 0);
//! 2. each model's ε_m = A_m(λ_s; τ_m)/A(λ_l), against the measured ε = A(λ_s)/A(λ_l);
//! 3. the two models whose ε_m bracket ε, weighted w = (ε − ε₁)/(ε₂ − ε₁) (the nearest model
//!    alone outside the family's range, and the pixel flagged);
//! 4. every band's L_path, T·Ed and S as that mixture of the two models at their τ_m, then the
//!    exact inversion Rrs = y/(1 + S·π·y), y = (L1 − L_path)/(T·Ed).
//!
//! Noise and calibration error at the pair's bands enter every band's Rrs through A: this is
//! how a design's NIR/SWIR SNR reaches the products (Wang & Gordon 2018).
//!
//! **Sun glint** (Wang & Bailey 2001, l2gen's `glint_opt`): where the scene has glint, the
//! processor knows the wind and each pixel's geometry, and takes the glint it expects away
//! before the fit: each family member's band glint (Cox–Munk through that member's own direct
//! transmittances) is added to its path radiance, so the fit and the inversion see
//! L1 − L_path − G. Pixels whose normalised glint L_GN = ρ_g μ₀/π exceeds 0.005 sr⁻¹ are left
//! out (l2gen's HIGLINT). Off (`glint: false`), the glint is read as aerosol.
//!
//! ## References
//! - Gordon, H. R. & Wang, M. (1994) Appl. Opt. 33, 443–452.
//! - Ahmad, Z. et al. (2010) New aerosol models for the retrieval of aerosol optical thickness
//!   and normalized water-leaving radiances from the SeaWiFS and MODIS sensors over coastal
//!   regions and open oceans. Appl. Opt. 49, 5545–5560.
//! - Wang, M. & Shi, W. (2007) The NIR-SWIR combined atmospheric correction approach for MODIS
//!   ocean color data processing. Opt. Express 15, 15722–15733.
//! - Wang, M. & Gordon, H. R. (2018) Sensor performance requirements for atmospheric correction
//!   of satellite ocean color remote sensing. Opt. Express 26, 7390–7403.

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use super::apply::{Level1Input, apply};
use super::dark::DarkSpectrumSettings;
use super::family::AerosolFamily;
pub(super) use super::mixture::{Mixture, PackedFamily};
pub(super) use super::nodes::{locate, weighted};
use super::{CorrectionError, Reflectance};
use crate::atmosphere::AerosolType;
use crate::control::RunControl;
use crate::instrument::SurfaceMap;
use crate::parse::FieldError;

/// How the correction finds the aerosol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum AerosolFit {
    /// Two-band model selection per pixel (Gordon & Wang 1994), with the NIR water-leaving
    /// iteration of Bailey et al. (2010) when `nir_iteration` is on.
    #[default]
    BandPair,
    /// Dark-spectrum fitting, one atmosphere per tile (Vanhellemont & Ruddick 2018; [`super::dark`]).
    DarkSpectrum,
}

/// Settings of the image-based correction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImageCorrection {
    /// How the aerosol is found.
    pub fit: AerosolFit,
    /// Centres of the short and long band of the aerosol pair, nm: the instrument's bands
    /// nearest them are used (l2gen's 748/869 for MODIS, 779/865 for OLCI; 1240/2130 or
    /// 1610/2200 as a SWIR pair). Band-pair fit only.
    pub pair_nm: [f64; 2],
    /// The NIR water-leaving reflectance at the pair's bands estimated from the red band and
    /// taken away before the aerosol fit, iterated (Bailey et al. 2010, as l2gen does it;
    /// [`super::nir_water`]). Band-pair fit only; needs bands near 443, 555 and 670 nm.
    pub nir_iteration: bool,
    /// Dark-spectrum fitting's settings.
    pub dark: DarkSpectrumSettings,
    /// The aerosol models of the family.
    pub models: Vec<AerosolType>,
    /// AOT(550) nodes of the family's tables (0 is always added).
    pub aot_nodes: Vec<f64>,
    /// Take away the sun glint expected from the wind and each pixel's geometry before the
    /// aerosol fit (Cox–Munk through each family member's own direct transmittances: l2gen's
    /// `glint_opt`, Wang & Bailey 2001), and leave out pixels whose normalised glint L_GN
    /// exceeds `glint_threshold_per_sr` (l2gen's HIGLINT). Only where the scene has glint: the
    /// processor knows the wind, as l2gen reads it from ancillary data.
    pub glint: bool,
    /// Largest normalised glint radiance L_GN = ρ_g μ₀/π a retrieved pixel may have, sr⁻¹
    /// (l2gen's `glint_thresh`, 0.005).
    pub glint_threshold_per_sr: f64,
    /// The error of the wind the processor assumes for the glint, m/s: its wind is the
    /// scene's plus this (at least 0). l2gen takes the wind from ancillary meteorological
    /// fields (NCEP), which over a lake or a reef are not the wind on the water; the glint
    /// it expects, and so what it takes away and which pixels it leaves out, follow the wind it
    /// assumes (Cox–Munk's slope variance grows with the wind: Cox & Munk 1954). 0: the
    /// processor knows the wind.
    pub glint_wind_error_m_s: f64,
    /// The cloud and shadow screen, where the scene has clouds ([`super::clouds`]).
    pub clouds: super::clouds::CloudScreen,
}

impl Default for ImageCorrection {
    fn default() -> Self {
        Self {
            fit: AerosolFit::BandPair,
            pair_nm: [779.0, 865.0],
            nir_iteration: true,
            dark: DarkSpectrumSettings::default(),
            models: vec![AerosolType::Maritime, AerosolType::Continental, AerosolType::Urban],
            aot_nodes: vec![0.05, 0.1, 0.2, 0.4, 0.8],
            glint: true,
            glint_threshold_per_sr: 0.005,
            glint_wind_error_m_s: 0.0,
            clouds: super::clouds::CloudScreen::default(),
        }
    }
}

/// The most AOT nodes a family may have (the default has 5; LUT interpolation gains nothing
/// from more than a few tens).
pub const MAX_AOT_NODES: usize = 32;

impl ImageCorrection {
    /// Dark-spectrum fitting with ACOLITE's two models (its MOD1 and MOD2 are continental and
    /// maritime). Urban and continental differ too little in the NIR for two adjacent bands to
    /// tell them apart: with all three, a noise-free continental scene fits urban at 885/900 nm
    /// with a smaller RMSD than continental (whose two lowest bands hold the water's residual).
    #[must_use]
    pub fn dark_spectrum() -> Self {
        Self {
            fit: AerosolFit::DarkSpectrum,
            models: vec![AerosolType::Maritime, AerosolType::Continental],
            ..Self::default()
        }
    }

    /// A short name for tables and menus.
    #[must_use]
    pub fn label(&self) -> String {
        match self.fit {
            AerosolFit::BandPair => format!(
                "{:.0}/{:.0} nm pair{}",
                self.pair_nm[0],
                self.pair_nm[1],
                if self.nir_iteration { ", NIR iteration" } else { "" }
            ),
            AerosolFit::DarkSpectrum if self.dark.tile_px == 0 => "dark spectrum, scene".into(),
            AerosolFit::DarkSpectrum => format!(
                "dark spectrum, {} px tiles{}",
                self.dark.tile_px,
                if self.dark.smooth_tiles { ", smoothed" } else { "" }
            ),
        }
    }
}

pub(super) fn invalid(field: &str, message: String) -> CorrectionError {
    CorrectionError::Invalid(FieldError { field: field.into(), message })
}

impl ImageCorrection {
    /// Check the settings against [`crate::ranges`].
    pub fn validate(&self) -> Result<(), CorrectionError> {
        let r = &crate::ranges::CORRECTION_PAIR_NM;
        for v in self.pair_nm {
            r.check(v).map_err(|m| invalid(r.path, m))?;
        }
        if self.pair_nm[0] >= self.pair_nm[1] {
            return Err(invalid(r.path, format!("{:?}: the short band first, then the long one", self.pair_nm)));
        }
        let repeated = self.models.iter().enumerate().any(|(i, m)| self.models[..i].contains(m));
        if self.models.is_empty() || self.models.contains(&AerosolType::None) || repeated {
            return Err(invalid(
                "correction.image.models",
                "one or more of maritime, continental, urban, each once (none is the family's τ = 0)".into(),
            ));
        }
        let a = &crate::ranges::CORRECTION_AOT_NODE;
        for &v in &self.aot_nodes {
            a.check(v).map_err(|m| invalid(a.path, m))?;
        }
        // Each node is a radiative transfer solve per model: the family's time grows with them.
        if self.aot_nodes.is_empty()
            || self.aot_nodes.len() > MAX_AOT_NODES
            || self.aot_nodes.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(invalid(
                a.path,
                format!("{} nodes (allowed: 1 to {MAX_AOT_NODES}, increasing)", self.aot_nodes.len()),
            ));
        }
        let g = &crate::ranges::CORRECTION_GLINT_THRESHOLD;
        g.check(self.glint_threshold_per_sr).map_err(|m| invalid(g.path, m))?;
        let w = &crate::ranges::CORRECTION_GLINT_WIND_ERROR;
        w.check(self.glint_wind_error_m_s).map_err(|m| invalid(w.path, m))?;
        self.clouds.validate()?;
        let d = &self.dark;
        let tile = &crate::ranges::CORRECTION_DARK_TILE_PX;
        tile.check(d.tile_px as f64).map_err(|m| invalid(tile.path, m))?;
        let px = &crate::ranges::CORRECTION_DARK_PIXELS;
        px.check(d.pixels as f64).map_err(|m| invalid(px.path, m))?;
        let gas = &crate::ranges::CORRECTION_DARK_MIN_GAS;
        gas.check(d.min_gas_transmittance).map_err(|m| invalid(gas.path, m))?;
        let w = &crate::ranges::CORRECTION_DARK_WAVE_RANGE_NM;
        for v in d.wave_range_nm {
            w.check(v).map_err(|m| invalid(w.path, m))?;
        }
        if d.wave_range_nm[0] >= d.wave_range_nm[1] {
            return Err(invalid(w.path, format!("{:?}: the shortest first", d.wave_range_nm)));
        }
        Ok(())
    }

    /// The instrument's bands nearest the pair's centres (short, long).
    pub fn pair(&self, centres_nm: &[f64]) -> Result<(usize, usize), CorrectionError> {
        let nearest = |target: f64| -> Result<usize, CorrectionError> {
            let (i, d) = centres_nm
                .iter()
                .enumerate()
                .map(|(i, c)| (i, (c - target).abs()))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .ok_or_else(|| invalid("correction.image.pair_nm", "the instrument has no bands".into()))?;
            if d > PAIR_TOLERANCE_NM {
                let have: Vec<String> = centres_nm.iter().map(|c| format!("{c:.0}")).collect();
                return Err(invalid(
                    "correction.image.pair_nm",
                    format!(
                        "no band within {PAIR_TOLERANCE_NM} nm of {target} nm (the instrument's centres: {} nm)",
                        have.join(", ")
                    ),
                ));
            }
            Ok(i)
        };
        let (s, l) = (nearest(self.pair_nm[0])?, nearest(self.pair_nm[1])?);
        if s == l {
            return Err(invalid("correction.image.pair_nm", format!("both ends pick the same band ({s})")));
        }
        Ok((s, l))
    }
}

/// How far a pair's centre may be from the band it picks, nm.
pub const PAIR_TOLERANCE_NM: f64 = 30.0;

/// The band pairs missions' processors take the aerosol from, in the order a design is offered
/// them when it lacks the pair asked for (nm): OLCI's 779/865 (l2gen), MODIS's 748/869 (l2gen;
/// Gordon & Wang 1994), the SWIR pairs of l2gen for OLI and MSI, 865/2200 and 1610/2200 (Wang &
/// Shi 2007), and 865/1610.
pub const MISSION_PAIRS_NM: [[f64; 2]; 5] =
    [[779.0, 865.0], [748.0, 869.0], [865.0, 2200.0], [1610.0, 2200.0], [865.0, 1610.0]];

impl ImageCorrection {
    /// This correction for a design with bands at `centres_nm`: unchanged where the bands make
    /// its pair (or it fits the dark spectrum, which needs none), else with the first of
    /// [`MISSION_PAIRS_NM`] they make ("the design's best pair"); `None` where they make none.
    #[must_use]
    pub fn for_bands(&self, centres_nm: &[f64]) -> Option<Self> {
        if self.fit == AerosolFit::DarkSpectrum || self.pair(centres_nm).is_ok() {
            return Some(self.clone());
        }
        MISSION_PAIRS_NM.iter().map(|&pair_nm| Self { pair_nm, ..self.clone() }).find(|c| c.pair(centres_nm).is_ok())
    }
}

/// What the correction found in each pixel.
#[derive(Debug, Clone)]
pub struct AerosolRetrieval {
    /// AOT(550), NaN where not retrieved (land, invalid pair bands).
    pub aot550: Array2<f32>,
    /// Ångström exponent 443–865 nm of the mixture, NaN where not retrieved.
    pub angstrom: Array2<f32>,
    /// Pixels whose measured ε lay outside the family's range (the nearest model used).
    pub outside_family: usize,
    /// Mean passes of the NIR water-leaving iteration over the retrieved pixels (1 without it).
    pub passes_mean: f64,
    /// Dark-spectrum fitting's tiles (empty for the band-pair fit).
    pub tiles: Vec<super::dark::TileFit>,
    /// Water pixels left out for high glint (L_GN above the threshold).
    pub high_glint: usize,
    /// The expected glint was taken away (the scene has glint and the correction's `glint` is on).
    pub glint_removed: bool,
    /// The measured ε at the pair over the retrieved pixels: median, 5th and 95th percentiles
    /// (the band-pair fit; NaN otherwise).
    pub epsilon: (f64, f64, f64),
    /// The band-pair fit: every member's ε for the median pixel (its long-band signal, the
    /// centre column), as the fit places a measured ε among them (empty for dark-spectrum
    /// fitting).
    pub members_epsilon: Vec<f64>,
}

/// One pixel of Level-1 as a fit sees it.
pub(super) struct Pixel<'a> {
    /// Row.
    pub row: usize,
    /// Column (the index of the family's terms is column·bands + band).
    pub col: usize,
    /// Bands.
    pub nb: usize,
    /// Calibrated radiance per band.
    pub l1: &'a [f32],
    /// Level-0 flags per band.
    pub flags: &'a [u8],
    /// The pixel is land (its Rrs is not retrieved).
    pub land: bool,
}

impl Pixel<'_> {
    /// Index of band `b` in the family's terms.
    pub fn at(&self, b: usize) -> usize {
        self.col * self.nb + b
    }
}

/// Correct `level1` with the family: see the module docs. A Level-1 handed over
/// ([`Level1Input::Owned`]) becomes the Rrs.
pub fn correct_image<'a>(
    level1: impl Into<Level1Input<'a>>,
    family: &AerosolFamily,
    settings: &ImageCorrection,
    bands: &crate::spectral::BandSet,
    surface: &SurfaceMap,
    control: &RunControl,
) -> Result<(Reflectance, AerosolRetrieval), CorrectionError> {
    let level1 = level1.into();
    let nb = level1.level1().radiance.dim().2;
    if nb != family.n_bands || family.terms.is_empty() || bands.len() != nb {
        return Err(invalid("correction.image", format!("the family has {} bands, Level-1 {nb}", family.n_bands)));
    }
    // The expected glint taken away: folded into every member's path radiance, so the fit and
    // the inversion see L1 − L_path − G (only where the scene has glint: `glint_lgn` is empty
    // otherwise, as the family's glint is zero).
    let folded;
    let glint_removed = settings.glint && !family.glint_lgn.is_empty();
    let family = if glint_removed {
        folded = family.with_glint_in_path();
        &folded
    } else {
        family
    };
    let high_glint =
        |col: usize| settings.glint && family.glint_lgn.get(col).is_some_and(|g| *g > settings.glint_threshold_per_sr);
    let (mut rrs, mut retrieval) = correct_with(level1, family, settings, bands, surface, control, &high_glint)?;
    // Left out already (invalid); flagged as glint too, so the flags say why.
    retrieval.high_glint = super::mark_high_glint(&mut rrs, &high_glint, surface);
    retrieval.glint_removed = glint_removed;
    Ok((rrs, retrieval))
}

/// [`correct_image`] with the family as the fit uses it; `high_glint(col)`: the column's pixels
/// are left out (flagged invalid).
fn correct_with(
    level1: Level1Input<'_>,
    family: &AerosolFamily,
    settings: &ImageCorrection,
    bands: &crate::spectral::BandSet,
    surface: &SurfaceMap,
    control: &RunControl,
    high_glint: &(dyn Fn(usize) -> bool + Sync),
) -> Result<(Reflectance, AerosolRetrieval), CorrectionError> {
    let packed = PackedFamily::new(family);
    match settings.fit {
        AerosolFit::BandPair => {
            let fit = super::pair::PairFit::new(family, &packed, settings, bands)?;
            let cols = level1.level1().radiance.dim().1;
            let (rrs, mut retrieval, long) =
                apply(level1, surface, control, |p, mix, scratch| !high_glint(p.col) && fit.fit(p, mix, scratch))?;
            let mut long: Vec<f64> = long.into_iter().filter(|v| v.is_finite()).map(f64::from).collect();
            let median = crate::metrics::nearest_rank(&mut long, 0.5);
            retrieval.members_epsilon = fit.member_epsilon(cols / 2, median);
            Ok((rrs, retrieval))
        }
        AerosolFit::DarkSpectrum => {
            let (rows, cols) = (level1.level1().radiance.dim().0, level1.level1().radiance.dim().1);
            if (0..cols).all(high_glint) {
                // Nothing to fit: every pixel is left out for glint.
                return apply(level1, surface, control, |_, _, _: &mut ()| false).map(|(r, a, _)| (r, a));
            }
            let tiles = super::dark::fit_tiles(level1.level1(), family, &settings.dark, bands, control, high_glint)?;
            let (rrs, mut retrieval, _) =
                if let Some(smooth) = super::dark::smoothed(&tiles, &settings.dark, rows, cols) {
                    apply(level1, surface, control, |p, mix, _: &mut ()| {
                        smooth.fill(family, &packed, p.row * cols + p.col, mix);
                        !high_glint(p.col)
                    })?
                } else {
                    let index = super::dark::tile_index(&tiles, rows, cols);
                    let mixtures: Vec<Mixture<'_>> = tiles.iter().map(|t| t.mixture(family, &packed)).collect();
                    apply(level1, surface, control, |p, mix, _: &mut ()| {
                        let m = &mixtures[index[p.row * cols + p.col]];
                        mix.entries.extend_from_slice(&m.entries);
                        (mix.aot550, mix.angstrom, mix.passes) = (m.aot550, m.angstrom, 1);
                        !high_glint(p.col)
                    })?
                };
            retrieval.tiles = tiles;
            Ok((rrs, retrieval))
        }
    }
}

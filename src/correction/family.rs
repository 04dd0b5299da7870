//! The image-based correction's aerosol family ([`super::image`]): one atmosphere per model and
//! AOT node from Shoal's own radiative transfer, and their band-effective terms over a run's
//! geometry (the photon-weighted means the forward model uses, `band_atmosphere::band_means`;
//! Vermote et al. 1997).

use super::CorrectionError;
use super::image::{ImageCorrection, invalid};
use crate::atmosphere::{AerosolType, AtmosphereLut, AtmosphereSpec, LutAxes};
use crate::control::RunControl;
use crate::instrument::band_atmosphere::band_terms_of_each;
pub use crate::instrument::band_atmosphere::{BandTerms, TERM_COLUMNS};
use crate::instrument::{Response, Viewing};
use crate::scene::Scene;
use crate::toa::PathOptics;
use rayon::prelude::*;

/// The family's tables: per model, per AOT node, per column and band.
#[derive(Debug, Clone)]
pub struct AerosolFamily {
    /// The models.
    pub models: Vec<AerosolType>,
    /// AOT(550) nodes, the first 0.
    pub aot550: Vec<f64>,
    /// Each model's Ångström exponent between 443 and 865 nm.
    pub angstrom: Vec<f64>,
    /// Bands.
    pub n_bands: usize,
    /// `terms[m][k]`: the band terms of model m at node k.
    pub terms: Vec<Vec<BandTerms>>,
    /// Two-way gas transmittance of every column and band: (T·Ed) of the Rayleigh atmosphere
    /// with its gases over the same without them (1 where the scene has no gases).
    pub gas_two_way: Vec<f64>,
    /// Per column: the normalised glint radiance L_GN = ρ_g μ₀/π expected at its geometry from
    /// the wind the processor assumes (Cox–Munk; Wang & Bailey 2001), sr⁻¹; zeros unless the scene has glint.
    pub glint_lgn: Vec<f64>,
}

impl AerosolFamily {
    /// The family with each member's glint added to its path radiance: what a processor that
    /// takes the expected glint away fits against.
    #[must_use]
    pub fn with_glint_in_path(&self) -> Self {
        let mut out = self.clone();
        out.terms.iter_mut().flatten().for_each(crate::instrument::band_atmosphere::BandTerms::fold_glint_into_path);
        out
    }
}

/// The family's atmospheres: one LUT per model and AOT node (the τ = 0 Rayleigh atmosphere
/// shared), over a run's LUT axes. Independent of the instrument's bands beyond the axes, so
/// two instruments over the same scene share it.
#[derive(Debug, Clone)]
pub struct FamilyLuts {
    /// The models.
    pub models: Vec<AerosolType>,
    /// AOT(550) nodes, the first 0.
    pub aot550: Vec<f64>,
    /// Each model's Ångström exponent between 443 and 865 nm.
    pub angstrom: Vec<f64>,
    /// `luts[m][k]`.
    pub luts: Vec<Vec<std::sync::Arc<AtmosphereLut>>>,
    /// The Rayleigh atmosphere without gases, where the scene has them (for the bands'
    /// gas transmittance).
    pub gas_free: Option<std::sync::Arc<AtmosphereLut>>,
    /// The sea surface the processor assumes: the scene's, its wind off by
    /// `glint_wind_error_m_s`. Its glint is what the family expects.
    pub surface: crate::atmosphere::SeaSurface,
}

/// The sea surface a processor with `settings` assumes over a scene with `surface`: the wind
/// off by the settings' error, at least 0 (a flat sea stays flat: no glint is expected).
#[must_use]
pub fn assumed_surface(
    surface: crate::atmosphere::SeaSurface,
    settings: &ImageCorrection,
) -> crate::atmosphere::SeaSurface {
    match surface {
        crate::atmosphere::SeaSurface::Wind { speed_m_s } => {
            crate::atmosphere::SeaSurface::Wind { speed_m_s: (speed_m_s + settings.glint_wind_error_m_s).max(0.0) }
        }
        flat => flat,
    }
}

impl FamilyLuts {
    /// Build the family's LUTs: `atmosphere` is the scene's (its aerosol and AOT replaced by
    /// each member's, its wind by the one the processor assumes: [`assumed_surface`]), `axes`
    /// the run's LUT axes. The sea's wind enters only the glint, not the radiative transfer
    /// (a flat Fresnel surface), so a wind error costs no other solve.
    pub fn build(
        settings: &ImageCorrection,
        atmosphere: &AtmosphereSpec,
        axes: &LutAxes,
        control: &RunControl,
    ) -> Result<Self, CorrectionError> {
        settings.validate()?;
        let atmosphere =
            &AtmosphereSpec { surface: assumed_surface(atmosphere.surface, settings), ..atmosphere.clone() };
        let fail = |e: String| invalid("correction.image", e);
        let lut_with = |spec: AtmosphereSpec| -> Result<std::sync::Arc<AtmosphereLut>, CorrectionError> {
            if control.cancelled() {
                return Err(CorrectionError::Cancelled);
            }
            let built = spec.build().map_err(|e| fail(e.to_string()))?;
            Ok(std::sync::Arc::new(AtmosphereLut::build(&built, axes.clone()).map_err(|e| fail(e.to_string()))?))
        };
        let mut aot550 = vec![0.0];
        aot550.extend_from_slice(&settings.aot_nodes);
        // Every atmosphere of the family, built side by side: a LUT's solves are parallel, but
        // its start and its assembly are not, and one LUT at a time left a core idle between.
        // τ = 0 is the same Rayleigh atmosphere for every model: built once, first; the
        // gas-free Rayleigh atmosphere, where the scene has gases, last.
        let mut specs = vec![AtmosphereSpec { aerosol: AerosolType::None, aot550: 0.0, ..atmosphere.clone() }];
        for &m in &settings.models {
            for &t in &settings.aot_nodes {
                specs.push(AtmosphereSpec { aerosol: m, aot550: t, ..atmosphere.clone() });
            }
        }
        if atmosphere.gases {
            specs.push(AtmosphereSpec { aerosol: AerosolType::None, aot550: 0.0, gases: false, ..atmosphere.clone() });
        }
        let built: Vec<Result<std::sync::Arc<AtmosphereLut>, CorrectionError>> =
            specs.into_par_iter().map(lut_with).collect();
        // The first failure in the order above, whichever thread met it first.
        let mut built = built.into_iter().collect::<Result<Vec<_>, _>>()?.into_iter();
        let mut next = || built.next().ok_or_else(|| fail("a member's atmosphere is missing".into()));
        let rayleigh = next()?;
        let mut luts = Vec::with_capacity(settings.models.len());
        let mut angstrom = Vec::with_capacity(settings.models.len());
        for &m in &settings.models {
            let mut row = vec![rayleigh.clone()];
            for _ in &settings.aot_nodes {
                row.push(next()?);
            }
            luts.push(row);
            let built = AtmosphereSpec { aerosol: m, aot550: 1.0, ..atmosphere.clone() }
                .build()
                .map_err(|e| fail(e.to_string()))?;
            let tau = |nm: f64| -> Result<f64, CorrectionError> {
                Ok(built.column(nm).map_err(|e| fail(e.to_string()))?.aerosol.map_or(0.0, |a| a.0))
            };
            angstrom.push(-(tau(865.0)? / tau(443.0)?).ln() / (865.0f64 / 443.0).ln());
        }
        let gas_free = if atmosphere.gases { Some(next()?) } else { None };
        Ok(Self { models: settings.models.clone(), aot550, angstrom, luts, gas_free, surface: atmosphere.surface })
    }
}

impl AerosolFamily {
    /// The family's band terms over an instrument's geometry and bands; `across_track`: the
    /// viewing's columns are a swath, computed at that many columns (see `band_terms_of_each`).
    pub fn tabulate(
        luts: &FamilyLuts,
        scene: &Scene,
        response: &Response,
        viewing: &Viewing,
        across_track: Option<usize>,
        control: &RunControl,
    ) -> Result<Self, CorrectionError> {
        if control.cancelled() {
            return Err(CorrectionError::Cancelled);
        }
        // Every LUT bound to each geometry group's grid: the Rayleigh atmosphere (shared by the
        // models' first node), each model's other nodes, and the gas-free one where there is one.
        let fail = |e: crate::scene::SceneError| invalid("correction.image", e.to_string());
        let first: Vec<PathOptics> = response
            .groups
            .iter()
            .map(|g| PathOptics::new(scene, &g.grid, luts.luts[0][0].clone()))
            .collect::<Result<_, _>>()
            .map_err(fail)?;
        // The others share the first's solar spectrum and node brackets on each grid.
        let bind = |lut: &std::sync::Arc<AtmosphereLut>| -> Result<Vec<PathOptics>, CorrectionError> {
            first.iter().map(|p| p.rebind(scene, lut.clone())).collect::<Result<Vec<_>, _>>().map_err(fail)
        };
        let mut bound = vec![first.clone()];
        for row in &luts.luts {
            for lut in &row[1..] {
                bound.push(bind(lut)?);
            }
        }
        if let Some(lut) = &luts.gas_free {
            bound.push(bind(lut)?);
        }
        let atmospheres: Vec<Vec<&PathOptics>> = bound.iter().map(|b| b.iter().collect()).collect();
        let mut all = band_terms_of_each(&atmospheres, viewing, response, across_track)
            .map_err(|e| invalid("correction.image", e.to_string()))?
            .into_iter();
        let mut next = || all.next().ok_or_else(|| invalid("correction.image", "a member's terms are missing".into()));
        let rayleigh = next()?;
        let mut terms = Vec::with_capacity(luts.models.len());
        for row in &luts.luts {
            let mut out = vec![rayleigh.clone()];
            for _ in &row[1..] {
                out.push(next()?);
            }
            terms.push(out);
        }
        let gas_two_way = match &luts.gas_free {
            Some(_) => {
                let free = next()?;
                rayleigh.t_ed.iter().zip(&free.t_ed).map(|(a, b)| if *b > 0.0 { a / b } else { 1.0 }).collect()
            }
            None => vec![1.0; rayleigh.t_ed.len()],
        };
        // Per column, the largest over the geometry groups (a filter imager's rows see the ground
        // from different angles).
        let glint_lgn = match luts.surface {
            crate::atmosphere::SeaSurface::Wind { speed_m_s } if scene.wants(crate::scene::Effect::SunGlint) => {
                super::column_lgn(viewing, speed_m_s, scene.spec.atmosphere.water_refractive_index)
            }
            _ => Vec::new(),
        };
        Ok(Self {
            glint_lgn,
            gas_two_way,
            models: luts.models.clone(),
            aot550: luts.aot550.clone(),
            angstrom: luts.angstrom.clone(),
            n_bands: response.n_bands(),
            terms,
        })
    }
}

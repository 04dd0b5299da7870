//! Top-of-atmosphere radiance of a scene: the water model at each ground point, coupled to the
//! atmosphere LUT, with the effects the scene calls for — and nothing else.
//!
//! Per wavelength of the simulation grid, for water (Vermote et al. 1997; Gordon & Wang 1994):
//!
//! L_TOA = L_path + T_up·Lw + L_glint + L_adj,  Lw = Rrs·Ed(0⁺)/(1 − S·π·Rrs)
//!
//! with L_path, T_up, S and Ed(0⁺) from the LUT (interpolated across its wavelength nodes,
//! log–log, then multiplied by the 1-nm solar spectrum and the gas transmittances), Rrs from the
//! Lee et al. model at the point's concentrations, depth and substrate mixture. Land reflects
//! Lambertian: L = L_path + T_up·ρ·Ed/(π(1 − Sρ)). Adjacency adds the diffuse part of the
//! upward transmittance seeing the environment's reflectance instead of the target's (see
//! [`adjacency`]).
//!
//! ## References
//! - Vermote, E. F., Tanré, D., Deuzé, J. L., Herman, M., Morcrette, J.-J. (1997) Second
//!   simulation of the satellite signal in the solar spectrum, 6S: an overview. IEEE TGRS 35,
//!   675–686.
//! - Gordon, H. R. & Wang, M. (1994) Retrieval of water-leaving radiance and aerosol optical
//!   thickness over the oceans with SeaWiFS: a preliminary algorithm. Appl. Opt. 33, 443–452.

pub mod adjacency;
mod path;

use std::sync::Arc;

use crate::atmosphere::{AtmosphereError, AtmosphereLut, Geometry};
use crate::parse::FieldError;
use crate::scene::{Effect, Scene, SceneError, Sky};
use crate::spectral::{Extrapolation, WavelengthGrid};
use crate::water::{
    Bottom, SingleScratch, SingleWater, SubstrateLibrary, SubstrateMix, WaterColumn, WaterGeometry, WaterModel,
};

pub use adjacency::Adjacency;
pub use path::PathOptics;

/// The atmosphere on the simulation grid for one sun/view geometry (physical units:
/// W m⁻² sr⁻¹ nm⁻¹ for radiances, W m⁻² nm⁻¹ for irradiances; gases included).
#[derive(Debug, Clone, PartialEq)]
pub struct PathSpectrum {
    /// Path radiance.
    pub l_path: Vec<f64>,
    /// Downwelling irradiance just above the surface (black water).
    pub ed: Vec<f64>,
    /// Its direct-beam part, μ₀·e^(−τ/μ₀)·E₀·T_gas: what a cloud's shadow takes away.
    pub ed_direct: Vec<f64>,
    /// Upward transmittance (direct + diffuse).
    pub t_up: Vec<f64>,
    /// Diffuse part of the upward transmittance.
    pub t_up_diffuse: Vec<f64>,
    /// Spherical albedo.
    pub spherical_albedo: Vec<f64>,
    /// Sun-glint radiance (zeros unless the scene calls for glint).
    pub glint: Vec<f64>,
    /// Share of the diffuse transmittance due to molecules (the rest is aerosol), for adjacency.
    pub rayleigh_share: Vec<f64>,
}

/// Everything needed to turn a ground point into TOA radiance, built once per scene and grid.
#[derive(Debug, Clone)]
pub struct SceneOptics {
    /// The atmosphere on the grid.
    path: PathOptics,
    water: WaterModel,
    substrates: Vec<Vec<f64>>,
    land: Option<Vec<f64>>,
    adjacency: Option<Adjacency>,
    /// The water model at band nodes only (`Fidelity::band_nodes`), if asked for.
    nodes_water: Option<NodeWater>,
}

/// The water model at a subset of the grid (band nodes): the SIOPs and substrates picked at the
/// nodes, so the model there gives bit for bit what the full grid gives at those wavelengths.
#[derive(Debug, Clone)]
struct NodeWater {
    /// Grid indices of the nodes, increasing.
    indices: Vec<usize>,
    water: WaterModel,
    /// The same model in single precision, when the fidelity asks for it.
    single: Option<SingleWater>,
    substrates: Vec<Vec<f64>>,
}

/// Per-thread working memory of [`SceneOptics::radiance`].
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    mix: Vec<f64>,
    rho_target: Vec<f64>,
    /// Ed in a cloud's shadow (the diffuse sky only).
    ed_shadow: Vec<f64>,
    /// Water evaluations with a bottom term (shallow), counted for tests and run reports.
    pub bottom_evaluations: u64,
    /// Water evaluations in all.
    pub water_evaluations: u64,
    /// The single-precision kernel's work buffers.
    single: SingleScratch,
}

/// What [`SceneOptics::radiance`] found at a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Water: `rrs` holds its above-surface remote-sensing reflectance.
    Water,
    /// Land: `rrs` holds zeros.
    Land,
    /// Cloud between the surface and the sensor: `rrs` holds zeros.
    Cloud,
}

impl SceneOptics {
    /// Bind a scene to a simulation grid and an atmosphere LUT built for that scene (its
    /// wavelength nodes must bracket the grid).
    pub fn new(scene: &Scene, grid: &WavelengthGrid, lut: Arc<AtmosphereLut>) -> Result<Self, SceneError> {
        let (spec, dir) = scene.spec.siop.load(scene.base_dir.as_deref())?;
        let water = WaterModel::new(spec.resolve(grid, dir.as_deref())?);
        let library = SubstrateLibrary::embedded()?;
        let substrates = scene
            .substrates
            .iter()
            .map(|(name, _)| library.mix_on_grid(&SubstrateMix { parts: vec![(name.clone(), 1.0)] }, grid))
            .collect::<Result<Vec<_>, _>>()?;
        let land = match &scene.spec.land {
            Some(l) => {
                let r = l.reflectance.sample(grid, Extrapolation::Clamp, scene.base_dir.as_deref())?;
                // A reflectance outside 0–1 is refused with its wavelength, not clamped.
                let range = &crate::ranges::SCENE_LAND_REFLECTANCE;
                if let Some((w, v)) = grid.wavelengths_nm().iter().zip(&r).find(|(_, v)| !range.contains(**v)) {
                    return Err(SceneError::Invalid(crate::parse::FieldError {
                        field: range.field("scene.").into(),
                        message: format!("{v} at {w} nm is out of range (allowed: {})", range.allowed()),
                    }));
                }
                Some(r)
            }
            None => None,
        };
        let adjacency = if scene.wants(Effect::Adjacency) { Some(Adjacency::new(scene)) } else { None };
        Ok(Self { path: PathOptics::new(scene, grid, lut)?, water, substrates, land, adjacency, nodes_water: None })
    }

    /// Evaluate water spectra per pixel only at the grid indices `indices` (increasing; see
    /// [`crate::instrument::Response::band_nodes`]) through [`Self::water_at_nodes`]. A scene
    /// with adjacency keeps the full grid: its environment term needs whole spectra.
    /// With `single_precision`, the spectra at the nodes come from the single-precision kernel
    /// (`Fidelity::water_single_precision`).
    pub fn with_band_nodes(mut self, indices: Vec<usize>, single_precision: bool) -> Result<Self, SceneError> {
        if self.adjacency.is_some() || indices.is_empty() {
            return Ok(self);
        }
        let water = WaterModel::new(self.water.siop().subset(&indices)?);
        let single = single_precision.then(|| SingleWater::new(&water));
        let substrates = self.substrates.iter().map(|r| indices.iter().map(|&i| r[i]).collect()).collect();
        self.nodes_water = Some(NodeWater { indices, water, single, substrates });
        Ok(self)
    }

    /// The grid indices of the band nodes, when per-pixel spectra are evaluated there.
    #[must_use]
    pub fn band_nodes(&self) -> Option<&[usize]> {
        self.nodes_water.as_ref().map(|n| n.indices.as_slice())
    }

    /// Rrs above the surface at the band nodes (`rrs`, one per node) at scene point (x, y):
    /// `Ok(false)` on land or without band nodes (the caller then takes [`Self::radiance`], as it
    /// does under a cloud or in its shadow).
    pub fn water_at_nodes(
        &self,
        scene: &Scene,
        x_m: f64,
        y_m: f64,
        g: &Geometry,
        scratch: &mut Scratch,
        rrs: &mut [f64],
    ) -> Result<bool, SceneError> {
        let Some(nodes) = &self.nodes_water else { return Ok(false) };
        if scene.is_land(x_m, y_m) {
            return Ok(false);
        }
        // The single-precision kernel's work buffer, out of `scratch` while the column borrows it.
        let mut single_scratch = std::mem::take(&mut scratch.single);
        let column = water_column(scene, x_m, y_m, &nodes.substrates, nodes.indices.len(), scratch);
        let geometry = WaterGeometry { sun_zenith_rad: g.sun_zenith_rad, view_zenith_rad: g.view_zenith_rad };
        let result = match &nodes.single {
            Some(single) => single.rrs_above_into(&column, &geometry, &mut single_scratch, rrs),
            None => nodes.water.rrs_above_into(&column, &geometry, rrs),
        };
        scratch.single = single_scratch;
        result?;
        Ok(true)
    }

    /// The simulation grid.
    #[must_use]
    pub fn grid(&self) -> &WavelengthGrid {
        self.path.grid()
    }

    /// The atmosphere on the grid (what [`Self::path_spectrum`] reads).
    #[must_use]
    pub fn path(&self) -> &PathOptics {
        &self.path
    }

    /// The water model (SIOP set on the grid).
    #[must_use]
    pub fn water(&self) -> &WaterModel {
        &self.water
    }

    /// Extraterrestrial irradiance on the grid at the scene's date, W m⁻² nm⁻¹.
    #[must_use]
    pub fn e0(&self) -> &[f64] {
        self.path.e0()
    }

    /// The path radiance's (Q/I, U/I) at `wavelength_nm` (linear in ln λ between the table's
    /// wavelength nodes, constant beyond its ends) in the view's meridian frame; `None` when the
    /// table holds no vector solution ([`AtmosphereLut::path_polarisation`]).
    pub fn path_polarisation(&self, g: &Geometry, wavelength_nm: f64) -> Result<Option<(f64, f64)>, AtmosphereError> {
        let lut = self.path.lut();
        let (j0, j1, t) = path::ln_bracket(&lut.axes().wavelengths_nm, wavelength_nm);
        let (Some(a), Some(b)) = (lut.path_polarisation(j0, g)?, lut.path_polarisation(j1, g)?) else {
            return Ok(None);
        };
        Ok(Some((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))))
    }

    /// The atmosphere on the grid for geometry `g` (LUT nodes interpolated log–log in λ, then
    /// the 1-nm solar spectrum and the gases applied).
    pub fn path_spectrum(&self, g: &Geometry) -> Result<PathSpectrum, AtmosphereError> {
        self.path.path_spectrum(g)
    }

    /// TOA radiance (`l_toa`, W m⁻² sr⁻¹ nm⁻¹) and, over water, Rrs (`rrs`, sr⁻¹) at scene point
    /// (x, y) m, seen along `g` through `path` under `sky` ([`Scene::sky_at`]).
    ///
    /// A cloud reflects as a Lambertian layer of its albedo (as land does, with R for ρ); in a
    /// cloud's shadow the surface is lit by the diffuse sky alone, Ed − Ed_direct, and shows no
    /// glint (the sun is hidden). Rrs is a property of the water, the same in shadow.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance(
        &self,
        scene: &Scene,
        x_m: f64,
        y_m: f64,
        g: &Geometry,
        sky: Sky,
        path: &PathSpectrum,
        scratch: &mut Scratch,
        l_toa: &mut [f64],
        rrs: &mut [f64],
    ) -> Result<Target, SceneError> {
        let n = self.path.grid().len();
        let shadow = sky == Sky::Shadow;
        let mut ed_shadow = std::mem::take(&mut scratch.ed_shadow);
        if shadow {
            ed_shadow.clear();
            ed_shadow.extend(path.ed.iter().zip(&path.ed_direct).map(|(e, d)| (e - d).max(0.0)));
        }
        let ed: &[f64] = if shadow { &ed_shadow } else { &path.ed };
        let cloud_albedo = scene.clouds.as_ref().map_or(0.0, |c| c.spec().albedo());
        let surface = if sky == Sky::Cloud {
            for i in 0..n {
                let lw =
                    cloud_albedo * ed[i] / (std::f64::consts::PI * (1.0 - path.spherical_albedo[i] * cloud_albedo));
                l_toa[i] = path.l_path[i] + path.t_up[i] * lw;
                rrs[i] = 0.0;
            }
            Target::Cloud
        } else if scene.is_land(x_m, y_m) {
            let Some(rho) = &self.land else {
                return Err(SceneError::Invalid(FieldError {
                    field: "land".into(),
                    message: "land mask without reflectance".into(),
                }));
            };
            for i in 0..n {
                let lw = rho[i] * ed[i] / (std::f64::consts::PI * (1.0 - path.spherical_albedo[i] * rho[i]));
                l_toa[i] = path.l_path[i] + path.t_up[i] * lw;
                rrs[i] = 0.0;
            }
            Target::Land
        } else {
            let column = water_column(scene, x_m, y_m, &self.substrates, n, scratch);
            let geometry = WaterGeometry { sun_zenith_rad: g.sun_zenith_rad, view_zenith_rad: g.view_zenith_rad };
            self.water.rrs_above_into(&column, &geometry, rrs)?;
            let glint = if shadow { 0.0 } else { 1.0 };
            for i in 0..n {
                let lw = rrs[i] * ed[i] / (1.0 - path.spherical_albedo[i] * std::f64::consts::PI * rrs[i]);
                l_toa[i] = path.l_path[i] + path.t_up[i] * lw + glint * path.glint[i];
            }
            Target::Water
        };
        if let Some(adj) = &self.adjacency {
            let land = self.land.as_deref().unwrap_or(&[]);
            scratch.rho_target.clear();
            match surface {
                Target::Water => scratch.rho_target.extend(rrs.iter().map(|r| std::f64::consts::PI * r)),
                Target::Land => scratch.rho_target.extend_from_slice(land),
                Target::Cloud => scratch.rho_target.resize(n, cloud_albedo),
            }
            adj.add(x_m, y_m, g, path, land, &scratch.rho_target, l_toa);
        }
        scratch.ed_shadow = ed_shadow;
        Ok(surface)
    }
}

/// The water column at scene point (x, y): the maps' concentrations and, in shallow scenes, the
/// depth and the substrate mixture on the `n` wavelengths `substrates` are sampled on (mixed
/// into `scratch`, whose evaluation counters it advances).
fn water_column<'a>(
    scene: &Scene,
    x_m: f64,
    y_m: f64,
    substrates: &[Vec<f64>],
    n: usize,
    scratch: &'a mut Scratch,
) -> WaterColumn<'a> {
    scratch.water_evaluations += 1;
    let bottom = match &scene.depth {
        Some(depth) => {
            let fractions: Vec<f64> = scene.substrates.iter().map(|(_, m)| m.value_at(x_m, y_m).max(0.0)).collect();
            let total: f64 = fractions.iter().sum();
            scratch.mix.clear();
            scratch.mix.resize(n, 0.0);
            for (f, r) in fractions.iter().zip(substrates) {
                // Fractions are normalised to sum 1; where all vanish the first substrate covers.
                let w = if total > 0.0 { f / total } else { 1.0 / substrates.len() as f64 };
                for (m, v) in scratch.mix.iter_mut().zip(r) {
                    *m += w * v;
                }
            }
            scratch.bottom_evaluations += 1;
            Bottom::Shallow { depth_m: depth.value_at(x_m, y_m), reflectance: &scratch.mix }
        }
        None => Bottom::OpticallyDeep,
    };
    WaterColumn {
        chl_mg_m3: scene.chl.value_at(x_m, y_m),
        cdom_per_m: scene.cdom.value_at(x_m, y_m),
        nap_g_m3: scene.nap.value_at(x_m, y_m),
        bottom,
    }
}

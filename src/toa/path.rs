//! The atmosphere on the simulation grid for one geometry ([`PathOptics::path_spectrum`]): the
//! LUT's normalised terms at its wavelength nodes, interpolated log–log in λ onto the grid, times
//! the 1-nm solar spectrum and the gas transmittances (the formulas of [`super`]'s docs).
//!
//! It is what the forward model, the band-effective atmosphere and the image-based correction's
//! aerosol family all read, so it is built apart from the water ([`super::SceneOptics`] holds
//! one): the family binds twenty atmospheres to one grid and needs no water model for them.
//! Two things a spectrum repeats are computed once: the logarithms of each LUT node's terms
//! (two per grid wavelength and term otherwise), and the gas factors, which depend on the
//! geometry and the gases but not on the aerosol ([`PathOptics::gas_legs`], shared by the
//! family's members through [`PathOptics::path_spectrum_with`]).

use std::sync::Arc;

use super::PathSpectrum;
use crate::atmosphere::{AtmosphereError, AtmosphereLut, GasAmounts, GasLegs, Geometry, Normalised};
use crate::scene::{Effect, Scene, SceneError};
use crate::spectral::WavelengthGrid;

/// A LUT bound to a simulation grid: what [`Self::path_spectrum`] needs.
#[derive(Debug, Clone)]
pub struct PathOptics {
    grid: WavelengthGrid,
    e0: Vec<f64>,
    lut: Arc<AtmosphereLut>,
    /// Per grid wavelength: bracketing LUT nodes and the weight in ln λ.
    nodes: Vec<(usize, usize, f64)>,
    /// The spherical albedo on the grid: it depends on no geometry, so it is interpolated once.
    spherical_albedo: Vec<f64>,
    glint: bool,
}

/// The LUT wavelength nodes either side of `wavelength_nm` and the weight of the upper one,
/// linear in ln λ; constant beyond the first and last node.
pub(super) fn ln_bracket(node_wl: &[f64], wavelength_nm: f64) -> (usize, usize, f64) {
    if node_wl.len() == 1 {
        return (0, 0, 0.0);
    }
    let j = node_wl.partition_point(|&v| v <= wavelength_nm).clamp(1, node_wl.len() - 1);
    let t = (wavelength_nm / node_wl[j - 1]).ln() / (node_wl[j] / node_wl[j - 1]).ln();
    (j - 1, j, t.clamp(0.0, 1.0))
}

/// The LUT's spherical albedo on the grid whose node brackets are `nodes` (log–log in λ).
fn spherical_albedo_on(lut: &AtmosphereLut, nodes: &[(usize, usize, f64)]) -> Vec<f64> {
    let albedo = lut.spherical_albedo_at_nodes();
    let ln_albedo: Vec<f64> = albedo.iter().map(|s| s.ln()).collect();
    nodes.iter().map(|&(j0, j1, t)| loglin(albedo[j0], albedo[j1], ln_albedo[j0], ln_albedo[j1], t)).collect()
}

/// One LUT node's terms and the logarithms of those interpolated log–log.
/// (The spherical albedo's are [`PathOptics::new`]'s: it depends on no geometry.)
struct Node {
    at: Normalised,
    /// τ_Rayleigh + τ_aerosol.
    tau: f64,
    ln_radiance: f64,
    ln_ed: f64,
    /// ln τ where the whole spectrum is asked for (band terms do not read τ), else NaN.
    ln_tau: f64,
    /// ln of the glint where the path has glint (0 and so −∞ otherwise, never read).
    ln_glint: f64,
}

impl Node {
    fn new(at: Normalised, full: bool, glint: bool) -> Self {
        let tau = at.tau_rayleigh + at.tau_aerosol;
        Self {
            tau,
            ln_radiance: at.radiance.ln(),
            ln_ed: at.ed.ln(),
            ln_tau: if full { tau.ln() } else { f64::NAN },
            ln_glint: if glint { at.glint.ln() } else { f64::NEG_INFINITY },
            at,
        }
    }
}

/// Between `a` and `b` at weight `t`: linear in the logarithms (`la`, `lb`: theirs) where both
/// are positive, else linear.
#[inline]
fn loglin(a: f64, b: f64, la: f64, lb: f64, t: f64) -> f64 {
    if a > 0.0 && b > 0.0 { (la + t * (lb - la)).exp() } else { a + t * (b - a) }
}

impl PathOptics {
    /// Bind `lut` (built for `scene`; its wavelength nodes must bracket the grid) to `grid`.
    pub fn new(scene: &Scene, grid: &WavelengthGrid, lut: Arc<AtmosphereLut>) -> Result<Self, SceneError> {
        let atmosphere = lut.atmosphere();
        let e0 = grid.wavelengths_nm().iter().map(|&w| atmosphere.e0(w)).collect::<Result<Vec<_>, _>>()?;
        let node_wl = &lut.axes().wavelengths_nm;
        let nodes = grid
            .wavelengths_nm()
            .iter()
            .map(|&w| {
                let (first, last) = (node_wl[0], node_wl[node_wl.len() - 1]);
                if w < first - 1e-9 || w > last + 1e-9 {
                    return Err(SceneError::Atmosphere(AtmosphereError::OutOfRange {
                        field: "wavelength_nm (LUT nodes)".into(),
                        value: w,
                        allowed: format!("{first} to {last} nm"),
                    }));
                }
                Ok(ln_bracket(node_wl, w))
            })
            .collect::<Result<Vec<_>, SceneError>>()?;
        let spherical_albedo = spherical_albedo_on(&lut, &nodes);
        Ok(Self { grid: grid.clone(), e0, lut, nodes, spherical_albedo, glint: scene.wants(Effect::SunGlint) })
    }

    /// [`Self::new`] of the same scene and grid with another `lut`: where that LUT has the same
    /// wavelength nodes and day (the image-based correction's family: one LUT per aerosol model
    /// and AOT), the solar spectrum and node brackets are this binding's, not computed again
    /// (every atmosphere's E₀ is TSIS-1 scaled to its day: `AtmosphereSpec::build`).
    pub fn rebind(&self, scene: &Scene, lut: Arc<AtmosphereLut>) -> Result<Self, SceneError> {
        let same_day = lut.atmosphere().spec().day_of_year == self.lut.atmosphere().spec().day_of_year;
        if !(same_day && lut.axes().wavelengths_nm == self.lut.axes().wavelengths_nm) {
            return Self::new(scene, &self.grid, lut);
        }
        let spherical_albedo = spherical_albedo_on(&lut, &self.nodes);
        Ok(Self { lut, spherical_albedo, ..self.clone() })
    }

    /// The simulation grid.
    #[must_use]
    pub fn grid(&self) -> &WavelengthGrid {
        &self.grid
    }

    /// Extraterrestrial irradiance on the grid at the scene's date, W m⁻² nm⁻¹.
    #[must_use]
    pub fn e0(&self) -> &[f64] {
        &self.e0
    }

    /// The atmosphere LUT.
    #[must_use]
    pub fn lut(&self) -> &Arc<AtmosphereLut> {
        &self.lut
    }

    /// What the gas factors depend on besides the geometry: paths with the same key and grid
    /// have the same [`Self::gas_legs`] at a geometry.
    #[must_use]
    pub fn gas_key(&self) -> Option<(GasAmounts, f64)> {
        self.lut.atmosphere().gas_key()
    }

    /// The gas factors on the grid along `g` ([`crate::atmosphere::Atmosphere::gas_legs`]).
    pub fn gas_legs(&self, g: &Geometry) -> Result<GasLegs, AtmosphereError> {
        self.lut.atmosphere().gas_legs(self.grid.wavelengths_nm(), g.sun_zenith_rad.cos(), g.view_zenith_rad.cos())
    }

    /// The atmosphere on the grid for geometry `g` (LUT nodes interpolated log–log in λ, then
    /// the 1-nm solar spectrum and the gases applied).
    pub fn path_spectrum(&self, g: &Geometry) -> Result<PathSpectrum, AtmosphereError> {
        self.path_spectrum_with(g, &self.gas_legs(g)?)
    }

    /// [`Self::path_spectrum`] with the gas factors `legs` given: [`Self::gas_legs`] of this
    /// path or of one with the same [`Self::gas_key`] and grid at the same geometry (legs that
    /// do not fit, checked, are not used: the path's own are computed instead).
    pub fn path_spectrum_with(&self, g: &Geometry, legs: &GasLegs) -> Result<PathSpectrum, AtmosphereError> {
        self.fill(g, legs, None)
    }

    /// What band-effective terms read of [`Self::path_spectrum_with`] — L_path, Ed, T_up, S
    /// and the glint — at the grid indices `needed` marks (a band's span of weights); every other
    /// entry is left 0, and `ed_direct`, `t_up_diffuse` and `rayleigh_share` are empty. The entries
    /// computed are the full spectrum's, bit for bit (the same formulas); the image-based
    /// correction's family reads twenty atmospheres this way, and its bands cover part of the grid.
    pub fn band_path_with(
        &self,
        g: &Geometry,
        legs: &GasLegs,
        needed: &[bool],
    ) -> Result<PathSpectrum, AtmosphereError> {
        self.fill(g, legs, Some(needed))
    }

    /// The spectrum along `g` with the gas factors `legs`: every entry, or (`needed`) only the
    /// band terms' at the marked indices.
    fn fill(&self, g: &Geometry, legs: &GasLegs, needed: Option<&[bool]>) -> Result<PathSpectrum, AtmosphereError> {
        let n = self.grid.len();
        let mu0 = g.sun_zenith_rad.cos();
        let fits = legs.wavelengths_nm == self.grid.wavelengths_nm()
            && legs.mu0 == mu0
            && legs.muv == g.view_zenith_rad.cos()
            && legs.key == self.gas_key();
        let own;
        let legs = if fits {
            legs
        } else {
            own = self.gas_legs(g)?;
            &own
        };
        let every = needed.is_none();
        let nodes: Vec<Node> =
            self.lut.normalised_all(g, self.glint)?.into_iter().map(|at| Node::new(at, every, self.glint)).collect();
        // What only the whole spectrum holds.
        let if_every = || if every { vec![0.0; n] } else { Vec::new() };
        let mut p = PathSpectrum {
            l_path: vec![0.0; n],
            ed: vec![0.0; n],
            ed_direct: if_every(),
            t_up: vec![0.0; n],
            t_up_diffuse: if_every(),
            spherical_albedo: vec![0.0; n],
            glint: vec![0.0; n],
            rayleigh_share: if_every(),
        };
        let lin = |a: f64, b: f64, t: f64| a + t * (b - a);
        for i in 0..n {
            let full = match needed {
                None => true,
                Some(m) if m.get(i).copied().unwrap_or(false) => false,
                Some(_) => continue,
            };
            let (j0, j1, t) = self.nodes[i];
            let (na, nb) = (&nodes[j0], &nodes[j1]);
            let (a, b) = (&na.at, &nb.at);
            // Ed carries the sun's leg; the upward factor the rest of the two-way transmittance
            // (band-model gases are not a product of legs: see `gas::two_way_transmittance`).
            let (tg0, tgv) = (legs.down[i], legs.up_after_down[i]);
            let e0 = self.e0[i];
            p.l_path[i] = loglin(a.radiance, b.radiance, na.ln_radiance, nb.ln_radiance, t) * e0 * tg0 * tgv;
            p.ed[i] = loglin(a.ed, b.ed, na.ln_ed, nb.ln_ed, t) * e0 * tg0;
            let t_up = lin(a.t_up, b.t_up, t);
            p.t_up[i] = t_up * tgv;
            p.spherical_albedo[i] = self.spherical_albedo[i];
            if self.glint {
                p.glint[i] = loglin(a.glint, b.glint, na.ln_glint, nb.ln_glint, t) * e0 * tg0 * tgv;
            }
            if !full {
                continue;
            }
            let tau = loglin(na.tau, nb.tau, na.ln_tau, nb.ln_tau, t);
            p.ed_direct[i] = (mu0 * (-tau / mu0).exp() * e0 * tg0).min(p.ed[i]);
            let t_dir = lin(a.t_up_direct, b.t_up_direct, t);
            p.t_up_diffuse[i] = (t_up - t_dir).max(0.0) * tgv;
            // Diffuse transmission by molecules vs aerosols, in proportion to their forward-
            // scattering depths ω·η·τ (η from each phase function: ½ for molecules, the Mie
            // table's forward share for the aerosol; see WavelengthColumn::forward_scattering).
            let dr = lin(a.forward_scattering.0, b.forward_scattering.0, t);
            let da = lin(a.forward_scattering.1, b.forward_scattering.1, t);
            p.rayleigh_share[i] = if dr + da > 0.0 { dr / (dr + da) } else { 1.0 };
        }
        Ok(p)
    }
}

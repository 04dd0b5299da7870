//! The atmosphere look-up table: built once per scene over wavelength, sun zenith and view
//! zenith, exact in relative azimuth, then evaluated per pixel.
//!
//! One SOS solve per (wavelength, sun zenith) node gives, at every view-zenith node, the Fourier
//! coefficients of the multiple-scattered path radiance and the single-scattering coefficients;
//! one transmittance solve per wavelength gives T_up at every view-zenith node and the spherical
//! albedo. The table stores these normalised (unit solar flux, gas-free) quantities; E₀ and gas
//! transmittances are applied on evaluation.
//!
//! Only smooth quantities are interpolated, bilinearly in the zenith angles: the Fourier
//! coefficients (azimuth enters through their exact cosine series) and the single-scattering
//! attenuation integrals; the phase functions are evaluated at the exact scattering angles. So
//! there is no interpolation in azimuth, where aerosol forward peaks make the radiance steep.

use rayon::prelude::*;

use super::AtmosphereError;
use super::rt::{Scatterers, SsCoefficients, WavelengthColumn, fourier_sum_with, solve_sun, solve_transmittance};
use super::single_scattering::ScatteringGeometry;
use super::spec::{Atmosphere, AtmosphereTerms, Geometry, Normalised};
use super::stokes;

/// Node positions of the table (the azimuth axis sets where `shoal bench` and tests probe; the
/// table itself is exact in azimuth).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LutAxes {
    /// Wavelengths, nm (band centres or a coarse grid).
    pub wavelengths_nm: Vec<f64>,
    /// Sun zenith nodes, degrees, increasing.
    pub sun_zenith_deg: Vec<f64>,
    /// View zenith nodes, degrees, increasing.
    pub view_zenith_deg: Vec<f64>,
    /// Relative azimuth nodes, degrees, increasing within 0–180 (the field is symmetric).
    pub relative_azimuth_deg: Vec<f64>,
}

impl LutAxes {
    /// Axes that cover sun zenith `sza_range` and view zenith up to `max_vza` (degrees), with
    /// nodes at most `steps` = (sun, view, azimuth) degrees apart; steps below 0.1° count as 0.1°.
    #[must_use]
    pub fn covering(wavelengths_nm: Vec<f64>, sza_range: (f64, f64), max_vza: f64, steps: (f64, f64, f64)) -> Self {
        let nodes = |lo: f64, hi: f64, step: f64| -> Vec<f64> {
            if !(hi - lo > 1e-9) {
                return vec![lo];
            }
            let step = if step.is_finite() { step.max(0.1) } else { hi - lo };
            let n = ((hi - lo) / step).ceil().max(1.0) as usize;
            (0..=n).map(|i| lo + (hi - lo) * i as f64 / n as f64).collect()
        };
        Self {
            wavelengths_nm,
            sun_zenith_deg: nodes(sza_range.0, sza_range.1, steps.0),
            view_zenith_deg: nodes(0.0, max_vza, steps.1),
            relative_azimuth_deg: nodes(0.0, 180.0, steps.2),
        }
    }

    fn validate(&self) -> Result<(), AtmosphereError> {
        let check = |name: &str, v: &[f64], lo: f64, hi: f64| {
            if v.is_empty() || v.windows(2).any(|w| w[1] <= w[0]) || v.iter().any(|x| !(lo..=hi).contains(x)) {
                return Err(AtmosphereError::OutOfRange {
                    field: format!("LUT axis {name}"),
                    value: v.first().copied().unwrap_or(f64::NAN),
                    allowed: format!("a non-empty increasing list within {lo}–{hi}"),
                });
            }
            Ok(())
        };
        check(
            "wavelengths_nm",
            &self.wavelengths_nm,
            crate::ranges::MIN_SIMULATED_NM,
            crate::ranges::MAX_SIMULATED_NM,
        )?;
        let (sun, view) = (&crate::ranges::GEOMETRY_SUN_ZENITH_DEG, &crate::ranges::GEOMETRY_VIEW_ZENITH_DEG);
        check("sun_zenith_deg", &self.sun_zenith_deg, sun.lo, sun.hi)?;
        check("view_zenith_deg", &self.view_zenith_deg, view.lo, view.hi)?;
        check("relative_azimuth_deg", &self.relative_azimuth_deg, 0.0, 180.0)
    }
}

/// The table. Index order: `[wavelength][sun][view]`.
#[derive(Debug, Clone)]
pub struct AtmosphereLut {
    axes: LutAxes,
    atmosphere: Atmosphere,
    /// Multiple-scattering Fourier coefficients, zero-padded to `n_fourier` per node.
    ms: Vec<f64>,
    n_fourier: usize,
    ss: Vec<SsCoefficients>,
    scatterers: Vec<Scatterers>,
    ed: Vec<f64>,
    t_up: Vec<f64>,
    t_up_direct: Vec<f64>,
    spherical_albedo: Vec<f64>,
    tau_total: Vec<f64>,
    /// The direct beam μ₀·e^(−τ/μ₀) at each (wavelength, sun) node, `[w * ns + s]`.
    direct_at_nodes: Vec<f64>,
    tau_rayleigh: Vec<f64>,
    forward_scattering: Vec<(f64, f64)>,
    /// Per node, the path's `[Q₀, Q₁, Q₂, U₁, U₂]` ([`super::stokes`]); empty when the table was
    /// built without the vector solution.
    qu: Vec<[f64; 5]>,
}

/// Bracketing nodes and weight for linear interpolation on `nodes`; `x` must lie within the
/// nodes (0.01° of slack for rounding), or the table would silently extrapolate.
fn bracket(name: &str, nodes: &[f64], x: f64) -> Result<(usize, usize, f64), AtmosphereError> {
    let (first, last) = (nodes[0], nodes[nodes.len() - 1]);
    if !(x >= first - 0.01 && x <= last + 0.01) {
        return Err(AtmosphereError::OutOfRange {
            field: format!("{name} (deg) for this LUT"),
            value: x,
            allowed: format!("{first} to {last} (the table's nodes; build it to cover the scene)"),
        });
    }
    if nodes.len() == 1 || x <= first {
        return Ok((0, 0, 0.0));
    }
    let k = nodes.len() - 1;
    if x >= last {
        return Ok((k, k, 0.0));
    }
    let j = nodes.partition_point(|&v| v <= x).clamp(1, k);
    Ok((j - 1, j, (x - nodes[j - 1]) / (nodes[j] - nodes[j - 1])))
}

/// A node bracket: lower and upper node and the upper one's weight.
type Bracket = (usize, usize, f64);
/// The four (sun, view) nodes of a geometry with their bilinear weights, and both brackets.
type Corners = ([(usize, usize, f64); 4], Bracket, Bracket);

/// The four (sun, view) nodes around `g` with their bilinear weights, and the brackets.
fn corners(a: &LutAxes, g: &Geometry) -> Result<Corners, AtmosphereError> {
    let (s0, s1, ts) = bracket("sun_zenith", &a.sun_zenith_deg, g.sun_zenith_rad.to_degrees())?;
    let (v0, v1, tv) = bracket("view_zenith", &a.view_zenith_deg, g.view_zenith_rad.to_degrees())?;
    let corners =
        [(s0, v0, (1.0 - ts) * (1.0 - tv)), (s0, v1, (1.0 - ts) * tv), (s1, v0, ts * (1.0 - tv)), (s1, v1, ts * tv)];
    Ok((corners, (s0, s1, ts), (v0, v1, tv)))
}

/// A geometry's table corners, brackets and cosines, shared by every wavelength node.
struct AtGeometry {
    corners: [(usize, usize, f64); 4],
    sun: (usize, usize, f64),
    view: (usize, usize, f64),
    mu0: f64,
    muv: f64,
    /// cos(mψ), ψ = π − Δφ, for each Fourier term m ([`fourier_sum_with`]).
    cos_m_psi: Vec<f64>,
    /// The scattering angles of the single-scattering paths.
    scattering: ScatteringGeometry,
}

impl AtmosphereLut {
    /// Build the table (parallel over wavelength × sun zenith in the caller's rayon pool).
    pub fn build(atmosphere: &Atmosphere, axes: LutAxes) -> Result<Self, AtmosphereError> {
        axes.validate()?;
        let acc = atmosphere.spec().accuracy;
        // Each wavelength's column (its aerosol's phase function moments) in parallel too; the
        // first failure in wavelength order, whichever thread met it first.
        let columns: Vec<Result<_, _>> = axes.wavelengths_nm.par_iter().map(|&w| atmosphere.column(w)).collect();
        let columns = columns.into_iter().collect::<Result<Vec<_>, _>>()?;
        let view_mu: Vec<f64> = axes.view_zenith_deg.iter().map(|v| v.to_radians().cos()).collect();
        let (nw, ns, nv) = (axes.wavelengths_nm.len(), axes.sun_zenith_deg.len(), axes.view_zenith_deg.len());
        let jobs: Vec<(usize, usize)> = (0..nw).flat_map(|w| (0..ns).map(move |s| (w, s))).collect();
        let sun: Vec<_> = jobs
            .par_iter()
            .map(|&(w, s)| solve_sun(&columns[w], axes.sun_zenith_deg[s].to_radians().cos(), &view_mu, &acc))
            .collect();
        let up: Vec<_> = columns.par_iter().map(|c| solve_transmittance(c, &view_mu, &acc)).collect();
        let n_fourier = sun.iter().flat_map(|s| s.ms_fourier.iter().map(Vec::len)).max().unwrap_or(1);
        let mut ms = vec![0.0; nw * ns * nv * n_fourier];
        let mut ss = vec![SsCoefficients::default(); nw * ns * nv];
        let mut ed = vec![0.0; nw * ns];
        // Q and U need the vector solution up to m = 2 at every node.
        let polarised = n_fourier >= 3 && sun.iter().all(|s| s.qu_fourier.len() == nv);
        let mut qu = if polarised { vec![[0.0; 5]; nw * ns * nv] } else { Vec::new() };
        for (job, sol) in jobs.iter().zip(&sun) {
            let (w, s) = *job;
            ed[w * ns + s] = sol.ed();
            for v in 0..nv {
                let node = (w * ns + s) * nv + v;
                ms[node * n_fourier..node * n_fourier + sol.ms_fourier[v].len()].copy_from_slice(&sol.ms_fourier[v]);
                ss[node] = sol.ss[v];
                if polarised {
                    qu[node] = sol.qu_fourier[v];
                }
            }
        }
        let scatterers = (0..nw).map(|w| sun[w * ns].scatterers.clone()).collect();
        let t_up = up.iter().flat_map(|t| t.t_up.iter().copied()).collect();
        let t_up_direct = up.iter().flat_map(|t| t.t_up_direct.iter().copied()).collect();
        let spherical_albedo = up.iter().map(|t| t.spherical_albedo).collect();
        let tau_total: Vec<f64> = columns.iter().map(|c| c.total_tau()).collect();
        let direct_at_nodes = tau_total
            .iter()
            .flat_map(|&tau| {
                axes.sun_zenith_deg.iter().map(move |s| s.to_radians().cos() * (-tau / s.to_radians().cos()).exp())
            })
            .collect();
        Ok(Self {
            tau_total,
            direct_at_nodes,
            tau_rayleigh: columns.iter().map(|c| c.tau_rayleigh).collect(),
            forward_scattering: columns.iter().map(WavelengthColumn::forward_scattering).collect(),
            axes,
            atmosphere: atmosphere.clone(),
            ms,
            n_fourier,
            ss,
            scatterers,
            ed,
            t_up,
            t_up_direct,
            spherical_albedo,
            qu,
        })
    }

    /// The path radiance's (Q/I, U/I) at wavelength node `w` and geometry `g`, in the meridian
    /// frame of the view ([`super::stokes`]); `None` when the table holds no vector solution
    /// (single-scattering mode, or the polarisation correction switched off).
    pub fn path_polarisation(&self, w: usize, g: &Geometry) -> Result<Option<(f64, f64)>, AtmosphereError> {
        if self.qu.is_empty() {
            return Ok(None);
        }
        let intensity = self.normalised_with(w, g, false)?.radiance;
        let a = &self.axes;
        let (ns, nv) = (a.sun_zenith_deg.len(), a.view_zenith_deg.len());
        let (corners, ..) = corners(a, g)?;
        let mut c = [0.0; 5];
        for &(s, v, weight) in &corners {
            for (acc, x) in c.iter_mut().zip(&self.qu[(w * ns + s) * nv + v]) {
                *acc += weight * x;
            }
        }
        let (q, u) = (stokes::q_sum(&c, g.relative_azimuth_rad), stokes::u_sum(&c, g.relative_azimuth_rad));
        Ok((intensity > 0.0).then(|| (q / intensity, u / intensity)))
    }

    /// The axes.
    #[must_use]
    pub fn axes(&self) -> &LutAxes {
        &self.axes
    }

    /// All terms for wavelength node `w` at geometry `g`, interpolated, with E₀ and gases.
    pub fn terms(&self, w: usize, g: &Geometry) -> Result<AtmosphereTerms, AtmosphereError> {
        self.atmosphere.assemble(&self.normalised(w, g)?)
    }

    /// The spherical albedo S at each wavelength node (it depends on no geometry).
    #[must_use]
    pub fn spherical_albedo_at_nodes(&self) -> &[f64] {
        &self.spherical_albedo
    }

    /// The atmosphere this table was built for.
    #[must_use]
    pub fn atmosphere(&self) -> &Atmosphere {
        &self.atmosphere
    }

    /// The gas-free terms per unit solar flux for wavelength node `w` at geometry `g`, sun glint
    /// included (over a wind-roughened surface).
    pub fn normalised(&self, w: usize, g: &Geometry) -> Result<Normalised, AtmosphereError> {
        self.normalised_with(w, g, true)
    }

    /// As [`Self::normalised`]; the Cox–Munk glint term is computed only when `glint` is true
    /// (a scene that does not ask for `SunGlint` gets 0 without the cost).
    pub fn normalised_with(&self, w: usize, g: &Geometry, glint: bool) -> Result<Normalised, AtmosphereError> {
        let at = self.at_geometry(g)?;
        let a = &self.axes;
        if w >= a.wavelengths_nm.len() {
            return Err(AtmosphereError::OutOfRange {
                field: "wavelength index".into(),
                value: w as f64,
                allowed: format!("0 to {}", a.wavelengths_nm.len() - 1),
            });
        }
        Ok(self.normalised_at(w, g, glint, &at, &mut vec![0.0; self.n_fourier]))
    }

    /// [`Self::normalised_with`] at every wavelength node, the geometry's part (its check, the
    /// table's corners, the cosines, the azimuth's Fourier cosines) computed once: the same
    /// values, for a spectrum along one geometry.
    pub fn normalised_all(&self, g: &Geometry, glint: bool) -> Result<Vec<Normalised>, AtmosphereError> {
        let at = self.at_geometry(g)?;
        let mut fourier = vec![0.0; self.n_fourier];
        Ok((0..self.axes.wavelengths_nm.len()).map(|w| self.normalised_at(w, g, glint, &at, &mut fourier)).collect())
    }

    /// What [`Self::normalised_at`] needs of geometry `g` alone.
    fn at_geometry(&self, g: &Geometry) -> Result<AtGeometry, AtmosphereError> {
        g.validate()?;
        let (corners, sun, view) = corners(&self.axes, g)?;
        let psi = std::f64::consts::PI - g.relative_azimuth_rad;
        let (mu0, muv) = (g.sun_zenith_rad.cos(), g.view_zenith_rad.cos());
        Ok(AtGeometry {
            corners,
            sun,
            view,
            mu0,
            muv,
            cos_m_psi: (0..self.n_fourier).map(|m| (m as f64 * psi).cos()).collect(),
            scattering: ScatteringGeometry::new(mu0, muv, g.relative_azimuth_rad),
        })
    }

    /// The terms at wavelength node `w` (checked by the caller) and geometry `g` ([`Self::at_geometry`]);
    /// `fourier` is scratch space of `n_fourier` values.
    fn normalised_at(&self, w: usize, g: &Geometry, glint: bool, at: &AtGeometry, fourier: &mut [f64]) -> Normalised {
        let a = &self.axes;
        let (ns, nv, nf) = (a.sun_zenith_deg.len(), a.view_zenith_deg.len(), self.n_fourier);
        let AtGeometry { ref corners, sun: (s0, s1, ts), view: (v0, v1, tv), mu0, muv, ref cos_m_psi, ref scattering } =
            *at;
        fourier.fill(0.0);
        for &(s, v, weight) in corners {
            let node = (w * ns + s) * nv + v;
            for (f, c) in fourier.iter_mut().zip(&self.ms[node * nf..(node + 1) * nf]) {
                *f += weight * c;
            }
        }
        let parts = corners.map(|(s, v, weight)| (weight, &self.ss[(w * ns + s) * nv + v]));
        let ss = SsCoefficients::weighted(&parts);
        let radiance = fourier_sum_with(fourier, cos_m_psi) + self.scatterers[w].single_scattering_at(&ss, scattering);
        let lerp = |x: f64, y: f64, t: f64| x + t * (y - x);
        let ed = lerp(self.ed[w * ns + s0], self.ed[w * ns + s1], ts);
        let t_up = lerp(self.t_up[w * nv + v0], self.t_up[w * nv + v1], tv);
        let t_up_direct = lerp(self.t_up_direct[w * nv + v0], self.t_up_direct[w * nv + v1], tv);
        // Normalised quantities scale smoothly with μ₀ where the direct beam dominates; the
        // interpolated Ed is rescaled by the exact direct-beam ratio at this sun angle.
        let tau = self.tau_total[w];
        let direct_nodes = lerp(self.direct_at_nodes[w * ns + s0], self.direct_at_nodes[w * ns + s1], ts);
        let ed = ed * (mu0 * (-tau / mu0).exp()) / direct_nodes;
        let glint = if glint { self.atmosphere.glint(g, tau) } else { 0.0 };
        Normalised {
            wavelength_nm: a.wavelengths_nm[w],
            tau_rayleigh: self.tau_rayleigh[w],
            tau_aerosol: tau - self.tau_rayleigh[w],
            mu0,
            muv,
            radiance,
            ed,
            t_up,
            t_up_direct,
            spherical_albedo: self.spherical_albedo[w],
            glint,
            forward_scattering: self.forward_scattering[w],
        }
    }
}

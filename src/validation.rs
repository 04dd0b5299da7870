//! Comparison of Shoal's atmosphere with OSOAA V2.0 reference runs, shared by the physics tests
//! and `shoal bench` (the reference files are embedded from `tests/data/osoaa/`, provenance in
//! `tests/data/PROVENANCE.md`).
//!
//! Like for like: OSOAA's Rayleigh optical depth is a Hansen–Travis-type fit 1.5–3 % below
//! Bodhaine et al. (1999), so every comparison runs Shoal with
//! [`RayleighDepth::OsoaaHansenTravis`](crate::atmosphere::RayleighDepth), the aerosol at
//! AOT(550) = 0.1, scale heights 8 km and 2 km, sea index 1.34, flat surface, no gases — the
//! reference's settings. Quantities compared:
//! - path reflectance ρ = π L_path/(E₀ μ₀) = I_toa/μ₀ with OSOAA's normalised radiance I = πL/E₀,
//!   over black water (`rho_osoaa_vec_flat`);
//! - t_down = Ed(0⁺)/(E₀μ₀) over black water (`t_down_osoaa_flat`);
//! - Ed(0⁺) of the water runs, which OSOAA computes coupled with the water: Shoal's black-water
//!   Ed(0⁺)/(1 − S·π·Rrs) with OSOAA's own Rrs;
//! - T_up against OSOAA's T_up_eff = (L_toa − L_path)/Lw of the water runs.

use crate::atmosphere::{
    AIR_DEPOLARIZATION, AerosolType, AtmosphereError, RayleighDepth, RtAccuracy, WavelengthColumn, mixture_optics,
    solve_sun, solve_transmittance,
};
use crate::spectral::Table;

/// OSOAA black-ocean path runs (Rayleigh-only rows, and continental at SZA 60 / VZA 0).
pub const PATH_COMPARE_CSV: &str = include_str!("../tests/data/osoaa/path_compare.csv");
/// OSOAA water runs (Lake Hume chl 10 at SZA 60, Heron 3 m sand at SZA 20; VZA 0).
pub const WATER_REF_CSV: &str = include_str!("../tests/data/osoaa/water_ref.csv");

/// One compared quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Case label (`"400 nm sza 20 vza 0 none"`).
    pub case: String,
    /// Quantity (`"rho_path"`, `"t_down"`, `"t_up"`, `"ed_0plus"`).
    pub quantity: &'static str,
    /// Aerosol model of the case.
    pub aerosol: AerosolType,
    /// Wavelength, nm.
    pub wavelength_nm: f64,
    /// Shoal's value.
    pub shoal: f64,
    /// OSOAA's value.
    pub osoaa: f64,
    /// OSOAA's water-leaving radiance as a fraction of its TOA radiance (water runs only; T_up_eff
    /// is a small difference of two large numbers when this is small).
    pub lw_fraction: Option<f64>,
}

impl Comparison {
    /// Relative error, %.
    #[must_use]
    pub fn error_pct(&self) -> f64 {
        100.0 * (self.shoal / self.osoaa - 1.0)
    }
}

fn column(wavelength_nm: f64, tau_rayleigh: f64, aerosol: AerosolType) -> Result<WavelengthColumn, AtmosphereError> {
    let aerosol = mixture_optics(aerosol, wavelength_nm)?.map(|o| (0.1 * o.extinction_ratio, o.ssa, o.phase));
    Ok(WavelengthColumn {
        wavelength_nm,
        tau_rayleigh,
        depolarization: AIR_DEPOLARIZATION,
        aerosol,
        rayleigh_scale_height_km: 8.0,
        aerosol_scale_height_km: 2.0,
        water_index: 1.34,
    })
}

fn parse_aerosol(text: &str) -> Result<AerosolType, AtmosphereError> {
    AerosolType::parse(text).map_err(AtmosphereError::Data)
}

/// Compare path reflectance and t_down with the black-ocean OSOAA rows (relative azimuth 90°).
pub fn compare_paths(acc: &RtAccuracy) -> Result<Vec<Comparison>, AtmosphereError> {
    let t = Table::parse(PATH_COMPARE_CSV, "path_compare.csv")?;
    let (wl, sza, vza) = (t.column_f64("wl_nm")?, t.column_f64("sza")?, t.column_f64("vza")?);
    let aer = t.column_str("aer")?;
    let (tau_r, rho, t_down) =
        (t.column_f64("tau_ray_osoaa")?, t.column_f64("rho_osoaa_vec_flat")?, t.column_f64("t_down_osoaa_flat")?);
    let mut out = Vec::new();
    for i in 0..t.len() {
        let kind = parse_aerosol(aer[i])?;
        debug_assert!((RayleighDepth::OsoaaHansenTravis.tau(wl[i], &Default::default()) - tau_r[i]).abs() < 1e-5);
        let c = column(wl[i], tau_r[i], kind)?;
        let (mu0, muv) = (sza[i].to_radians().cos(), vza[i].to_radians().cos());
        let s = solve_sun(&c, mu0, &[muv], acc);
        let case = format!("{} nm sza {} vza {} {}", wl[i], sza[i], vza[i], aer[i]);
        let rho_shoal = std::f64::consts::PI * s.radiance(0, 90f64.to_radians()) / mu0;
        out.push(Comparison {
            case: case.clone(),
            quantity: "rho_path",
            aerosol: kind,
            wavelength_nm: wl[i],
            shoal: rho_shoal,
            osoaa: rho[i],
            lw_fraction: None,
        });
        out.push(Comparison {
            case,
            quantity: "t_down",
            aerosol: kind,
            wavelength_nm: wl[i],
            shoal: s.ed() / mu0,
            osoaa: t_down[i],
            lw_fraction: None,
        });
    }
    Ok(out)
}

/// Compare T_up, coupled Ed(0⁺) and path radiance with the OSOAA water runs (vector, flat).
pub fn compare_water_runs(acc: &RtAccuracy) -> Result<Vec<Comparison>, AtmosphereError> {
    let t = Table::parse(WATER_REF_CSV, "water_ref.csv")?;
    let (scenario, rt, wind) = (t.column_str("scenario")?, t.column_str("rt")?, t.column_f64("wind")?);
    let (wl, sza, vza, phi) =
        (t.column_f64("wl_nm")?, t.column_f64("sza")?, t.column_f64("vza")?, t.column_f64("phi")?);
    let aer = t.column_str("aer")?;
    let (tau_r, e0, rrs) = (t.column_f64("tau_ray")?, t.column_f64("E0")?, t.column_f64("Rrs")?);
    let (t_up, ed, l_path, lw, l_toa) = (
        t.column_f64("T_up_eff")?,
        t.column_f64("Ed_0p")?,
        t.column_f64("L_path")?,
        t.column_f64("Lw")?,
        t.column_f64("L_toa")?,
    );
    let mut out = Vec::new();
    for i in (0..t.len()).filter(|&i| rt[i] == "vector" && wind[i] == 0.0) {
        let kind = parse_aerosol(aer[i])?;
        let c = column(wl[i], tau_r[i], kind)?;
        let (mu0, muv) = (sza[i].to_radians().cos(), vza[i].to_radians().cos());
        let s = solve_sun(&c, mu0, &[muv], acc);
        let up = solve_transmittance(&c, &[muv], acc);
        let case = format!("{} {} nm sza {} vza {}", scenario[i], wl[i], sza[i], vza[i]);
        let fraction = Some(lw[i] / l_toa[i]);
        let coupled = s.ed() * e0[i] / (1.0 - up.spherical_albedo * std::f64::consts::PI * rrs[i]);
        let l_path_shoal = s.radiance(0, phi[i].to_radians()) * e0[i];
        for (quantity, shoal, osoaa) in
            [("t_up", up.t_up[0], t_up[i]), ("ed_0plus", coupled, ed[i]), ("l_path", l_path_shoal, l_path[i])]
        {
            out.push(Comparison {
                case: case.clone(),
                quantity,
                aerosol: kind,
                wavelength_nm: wl[i],
                shoal,
                osoaa,
                lw_fraction: fraction,
            });
        }
    }
    Ok(out)
}

/// Compare the polarised radiance at the top of the atmosphere, √(Q² + U²), with OSOAA's
/// (its degree of linear polarisation times its TOA radiance) on the flat-surface vector rows.
/// Shoal's is the path's (the vector solution, [`crate::atmosphere::stokes`]): the water-leaving
/// radiance is taken as unpolarised, as the instrument's polarisation effect takes it.
pub fn compare_polarisation(acc: &RtAccuracy) -> Result<Vec<Comparison>, AtmosphereError> {
    use crate::atmosphere::stokes;
    let t = Table::parse(WATER_REF_CSV, "water_ref.csv")?;
    let (scenario, rt, wind) = (t.column_str("scenario")?, t.column_str("rt")?, t.column_f64("wind")?);
    let (wl, sza, vza, phi) =
        (t.column_f64("wl_nm")?, t.column_f64("sza")?, t.column_f64("vza")?, t.column_f64("phi")?);
    let (aer, tau_r, e0) = (t.column_str("aer")?, t.column_f64("tau_ray")?, t.column_f64("E0")?);
    let (dolp, l_toa, lw) = (t.column_f64("dolp_toa_pct")?, t.column_f64("L_toa")?, t.column_f64("Lw")?);
    let mut out = Vec::new();
    for i in (0..t.len()).filter(|&i| rt[i] == "vector" && wind[i] == 0.0) {
        let kind = parse_aerosol(aer[i])?;
        let c = column(wl[i], tau_r[i], kind)?;
        let (mu0, muv) = (sza[i].to_radians().cos(), vza[i].to_radians().cos());
        // A second, off-nadir view keeps the azimuthal terms m ≤ 2 that Q and U need at nadir.
        let s = solve_sun(&c, mu0, &[muv, 0.9], acc);
        let Some(qu) = s.qu_fourier.first() else { continue };
        let dphi = phi[i].to_radians();
        let shoal = stokes::q_sum(qu, dphi).hypot(stokes::u_sum(qu, dphi)) * e0[i];
        out.push(Comparison {
            case: format!("{} {} nm sza {} vza {}", scenario[i], wl[i], sza[i], vza[i]),
            quantity: "polarised_radiance",
            aerosol: kind,
            wavelength_nm: wl[i],
            shoal,
            osoaa: dolp[i] / 100.0 * l_toa[i],
            lw_fraction: Some(lw[i] / l_toa[i]),
        });
    }
    Ok(out)
}

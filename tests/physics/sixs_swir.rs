//! The atmosphere from 865 to 2250 nm against 6SV 1.1, on the reference rows in
//! `tests/data/sixs/swir_reference.csv` (provenance in `tests/data/PROVENANCE.md`): three cases
//! (maritime and continental aerosol, water vapour 0.5–4 cm, a target at 1 km), ten wavelengths
//! and three Sentinel-2A bands. Shoal runs its own optics — Bodhaine Rayleigh depth, WMO Mie
//! aerosol, scalar successive orders — over a black surface (water refractive index 1: no Fresnel
//! reflection, as 6SV's black Lambertian ground), with gases.
//!
//! What is compared and why the tolerances are what they are:
//! - **gas transmittance** (two-way): Shoal's SWIR gas table is 6SV's own band model tabulated
//!   against path amount (`assets/atmosphere/gas_transmittance_6sv.csv`), so this checks the
//!   table and its interpolation in amount, air mass and pressure, not an independent model.
//! - **optical depths**: independent (Shoal's Bodhaine formula and Mie code against 6SV's).
//! - **path reflectance** without gases: independent radiative transfer (scalar here, vector in
//!   6SV). With WCP-55's components (what OSOAA uses) the aerosol itself differs from 6SV's in
//!   the SWIR; with 6SV's own component tables (`continental-6sv`, `maritime-6sv`) it does not,
//!   and the comparison is of the radiative transfer alone.

use shoal::atmosphere::{AerosolType, Atmosphere, AtmosphereSpec, GasAmounts, Geometry};
use shoal::spectral::Table;

use crate::data;

/// One reference row and Shoal's value of each quantity.
struct Compared {
    label: String,
    quantity: &'static str,
    shoal: f64,
    sixs: f64,
}

impl Compared {
    fn error_pct(&self) -> f64 {
        100.0 * (self.shoal / self.sixs - 1.0)
    }
}

/// The row's atmosphere; `sixs_tables`: its aerosol model built from 6SV's own component
/// tables (`continental-6sv`, `maritime-6sv`) instead of WCP-55's.
fn atmosphere(t: &Table, i: usize, sixs_tables: bool) -> Atmosphere {
    let num = |c: &str| t.column_f64(c).unwrap()[i];
    let name = t.column_str("aerosol").unwrap()[i];
    let aerosol = AerosolType::parse(&if sixs_tables { format!("{name}-6sv") } else { name.to_string() }).unwrap();
    AtmosphereSpec {
        aerosol,
        aot550: num("aot550"),
        pressure_hpa: num("pressure_hpa"),
        gases: true,
        gas_amounts: GasAmounts { ozone_atm_cm: num("ozone_atm_cm"), water_vapour_cm: num("water_vapour_cm") },
        // A black surface, as 6SV's black Lambertian ground: no Fresnel-reflected sky light.
        water_refractive_index: 1.0,
        day_of_year: 172,
        ..AtmosphereSpec::default()
    }
    .build()
    .unwrap()
}

/// (transmittance, τ_R, τ_a, ρ_path without gases) at `wavelength_nm`.
fn at(atm: &Atmosphere, g: &Geometry, wavelength_nm: f64) -> [f64; 4] {
    let t = atm.terms(wavelength_nm, g).unwrap();
    [t.t_gas, t.tau_rayleigh, t.tau_aerosol, t.rho_path / t.t_gas]
}

/// Band averages over the Sentinel-2A SRF weighted by SRF × E₀ (6SV's band integration): the
/// gas transmittance at every nanometre, the RT terms every 5 nm (they vary smoothly).
fn band(atm: &Atmosphere, g: &Geometry, name: &str) -> [f64; 4] {
    let srf = Table::from_asset("srf/srf_s2a_msi.csv").unwrap();
    let w = srf.column_f64("wavelength_nm").unwrap();
    let r = srf.column_f64(name).unwrap();
    let (mut gas, mut gas_w) = (0.0, 0.0);
    let mut rt = [0.0; 3];
    let mut rt_w = 0.0;
    for (&wl, &s) in w.iter().zip(&r) {
        if s <= 1e-3 {
            continue;
        }
        let weight = s * atm.e0(wl).unwrap();
        let (mu0, muv) = (g.sun_zenith_rad.cos(), g.view_zenith_rad.cos());
        gas += weight * atm.gas_two_way(wl, mu0, muv).unwrap();
        gas_w += weight;
        if (wl as i64) % 5 == 0 {
            let v = at(atm, g, wl);
            for k in 0..3 {
                rt[k] += weight * v[k + 1];
            }
            rt_w += weight;
        }
    }
    [gas / gas_w, rt[0] / rt_w, rt[1] / rt_w, rt[2] / rt_w]
}

fn compare(sixs_tables: bool) -> Vec<Compared> {
    let t = Table::from_file(&data("sixs/swir_reference.csv")).unwrap();
    let mut out = Vec::new();
    for i in 0..t.len() {
        let num = |c: &str| t.column_f64(c).unwrap()[i];
        let atm = atmosphere(&t, i, sixs_tables);
        let g = Geometry::from_degrees(num("sun_zenith_deg"), num("view_zenith_deg"), num("relative_azimuth_deg"));
        let name = t.column_str("band").unwrap()[i];
        let shoal = match name.strip_suffix("nm") {
            Some(wl) => at(&atm, &g, wl.parse().unwrap()),
            None => band(&atm, &g, name.trim_start_matches("S2A_")),
        };
        let label = format!("{} {name}", t.column_str("case").unwrap()[i]);
        let sixs = [num("t_gas_two_way"), num("tau_rayleigh"), num("tau_aerosol"), num("rho_path")];
        for (k, quantity) in ["t_gas", "tau_rayleigh", "tau_aerosol", "rho_path"].into_iter().enumerate() {
            out.push(Compared { label: label.clone(), quantity, shoal: shoal[k], sixs: sixs[k] });
        }
    }
    out
}

/// The largest |error| in % of `quantity` over the rows `keep` accepts, and where.
fn worst_of(rows: &[Compared], quantity: &str, keep: &dyn Fn(&Compared) -> bool) -> (f64, String) {
    rows.iter()
        .filter(|r| r.quantity == quantity && keep(r))
        .map(|r| (r.error_pct().abs(), format!("{}: shoal {:.5} 6SV {:.5}", r.label, r.shoal, r.sixs)))
        .fold((0.0, String::new()), |a, b| if b.0 > a.0 { b } else { a })
}

/// The rows of `quantities` as a Markdown table body (stderr, for the record).
fn print_rows(rows: &[Compared], quantities: &[&str]) {
    for r in rows.iter().filter(|r| quantities.is_empty() || quantities.contains(&r.quantity)) {
        eprintln!("| {} | {} | {:.5} | {:.5} | {:+.2} % |", r.label, r.quantity, r.shoal, r.sixs, r.error_pct());
    }
}

#[test]
fn swir_atmosphere_matches_6sv() {
    let rows = compare(false);
    print_rows(&rows, &[]);
    let worst = |quantity: &str, keep: &dyn Fn(&Compared) -> bool| worst_of(&rows, quantity, keep);
    let sea_level = |r: &Compared| !r.label.starts_with('C');
    let swir_nm =
        |r: &Compared| r.label.split(' ').nth(1).and_then(|w| w.strip_suffix("nm")).and_then(|w| w.parse::<f64>().ok());
    let swir =
        |r: &Compared| swir_nm(r).is_some_and(|w| w > 1000.0) || r.label.contains("B11") || r.label.contains("B12");
    // Gas, sea level, 1000–2500 nm (T ≥ 0.01: below, a relative error of a vanishing signal
    // says nothing): the table is 6SV's band model, so only the interpolation in slant water
    // column and air mass differs. Measured 0.17 %.
    let (e, at) = worst("t_gas", &|r| sea_level(r) && swir(r) && r.sixs >= 0.01);
    assert!(e < 0.3, "SWIR gas transmittance at sea level: {e:.2} % at {at}");
    // Below 1000 nm (865 nm, B8A) Shoal's gases are WASI's Gregg & Carder model, independent of
    // 6SV: measured 0.74 % (B8A, 4 cm of water vapour, air mass 3.2).
    let (e, at) = worst("t_gas", &|r| sea_level(r) && !swir(r));
    assert!(e < 1.0, "VNIR gas transmittance: {e:.2} % at {at}");
    // At 1 km (899 hPa) the mixed gases' column shrinks with pressure in Shoal as in 6SV, but
    // water vapour's lines also narrow at low pressure, which the table does not model: window
    // bands measured within 1.43 % (2200 nm); the saturated 1375 nm band (T = 0.23) is 37 % low
    // and is left out.
    let (e, at) = worst("t_gas", &|r| !sea_level(r) && r.sixs > 0.5);
    assert!(e < 2.0, "gas transmittance at 1 km, windows: {e:.2} % at {at}");
    // Rayleigh depth: Bodhaine et al. (1999) against 6SV's own formula, measured 1.85 % where
    // τ_R < 0.001 (2250 nm).
    let (e, at) = worst("tau_rayleigh", &|_| true);
    assert!(e < 2.5, "Rayleigh depth: {e:.2} % at {at}");
    // Aerosol depth, maritime: Shoal's Mie of the WMO components (OSOAA's tables) against 6SV's
    // maritime model; measured 6.0 % (1610 nm).
    let maritime = |r: &Compared| !r.label.starts_with('B');
    let (e, at) = worst("tau_aerosol", &|r| maritime(r));
    assert!(e < 7.0, "maritime aerosol depth: {e:.2} % at {at}");
    // Continental to 1650 nm: measured 9.3 %. Beyond 2 µm Shoal's is 30–32 % lower: 6SV's
    // components are not WCP-55's but d'Almeida et al. (1991)'s (DUST.f, WATE.f, SOOT.f), with
    // other sizes (6SV's continental has 0.012 % of its particles dust-like and 51 % soot, WCP-55's
    // 2.3e-4 % and 6 %), so 6SV's continental keeps 22 % of its 550 nm extinction at 2250 nm
    // where WCP-55's keeps 15 %. With 6SV's own tables (`continental-6sv`) the difference goes
    // (`swir_atmosphere_with_6svs_aerosol_tables_matches_6sv`).
    let (e, at) =
        worst("tau_aerosol", &|r| !maritime(r) && swir_nm(r).is_none_or(|w| w < 2000.0) && !r.label.contains("B12"));
    assert!(e < 10.0, "continental aerosol depth to 1650 nm: {e:.2} % at {at}");
    let (e, at) = worst("tau_aerosol", &|r| !maritime(r));
    assert!(e < 33.0, "continental aerosol depth beyond 2 µm moved from the documented 32 %: {e:.2} % at {at}");
    // Path reflectance without gases, to 1240 nm: independent radiative transfer, measured
    // 4.0 % (scalar SOS against vector 6SV, and the aerosol models' differences above).
    let (e, at) = worst("rho_path", &|r| swir_nm(r).is_some_and(|w| w <= 1240.0) || r.label.contains("B8A"));
    assert!(e < 5.0, "path reflectance to 1240 nm: {e:.2} % at {at}");
    // From 1375 nm the maritime aerosol makes the difference: Shoal's scatters more (single-
    // scattering albedo 0.98 against 6SV's 0.97 at 1650 nm and 0.89 at 2250 nm, next test), so
    // its path reflectance is up to 14 % higher at 1.6 µm and up to 48 % higher at 2.1–2.25 µm
    // (a path reflectance of 0.002–0.003). Held at the measured values so that a change shows.
    let (e, at) =
        worst("rho_path", &|r| swir_nm(r).is_some_and(|w| (1300.0..2000.0).contains(&w)) || r.label.contains("B11"));
    assert!(e < 14.0, "path reflectance 1375–1650 nm: {e:.2} % at {at}");
    let (e, at) = worst("rho_path", &|_| true);
    assert!(e < 49.0, "path reflectance 2.1–2.25 µm: {e:.2} % at {at}");
}

/// Shoal's WMO mixtures (OSOAA's component tables through Shoal's Mie code) against 6SV's own
/// models (`assets/atmosphere/aerosol_6sv_models.csv`): the cause of the SWIR path-reflectance
/// differences, printed for the record and held so that a change shows.
#[test]
fn aerosol_models_in_the_swir_against_6sv_models() {
    let t = Table::from_asset("atmosphere/aerosol_6sv_models.csv").unwrap();
    let (model, wl) = (t.column_str("model").unwrap(), t.column_f64("wavelength_nm").unwrap());
    let (ext, ssa, g) = (t.column_f64("nor_ext").unwrap(), t.column_f64("ssa").unwrap(), t.column_f64("g").unwrap());
    for i in 0..t.len() {
        let Ok(kind) = AerosolType::parse(model[i]) else { continue };
        if !(860.0..=2250.0).contains(&wl[i]) || kind == AerosolType::Urban {
            continue;
        }
        let o = shoal::atmosphere::mixture_optics(kind, wl[i]).unwrap().unwrap();
        // Measured: maritime extinction ratio within 6.1 % and single-scattering albedo within
        // 11.1 % (0.984 against 0.886 at 2250 nm); continental within 34 % and 13.7 % (1950 nm).
        let (e_ext, e_ssa) = ((o.extinction_ratio / ext[i] - 1.0).abs(), (o.ssa / ssa[i] - 1.0).abs());
        let (max_ext, max_ssa) = if kind == AerosolType::Maritime { (0.065, 0.115) } else { (0.35, 0.14) };
        assert!(
            e_ext < max_ext && e_ssa < max_ssa,
            "{} at {} nm: extinction {e_ext:.3}, SSA {e_ssa:.3}",
            model[i],
            wl[i]
        );
        eprintln!(
            "| {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.3} | {:.3} |",
            model[i],
            wl[i],
            o.extinction_ratio,
            ext[i],
            o.ssa,
            ssa[i],
            o.phase.asymmetry(),
            g[i]
        );
    }
}

/// The same rows with the aerosol built from 6SV's own component tables
/// (`shoal::atmosphere::aerosol_6sv`): the aerosol depth is then 6SV's, and what is left in the
/// path reflectance is the radiative transfer (scalar successive orders against vector 6SV, the
/// phase function read from 6SV's 83-angle tables) and 6SV's spectral interpolation.
#[test]
fn swir_atmosphere_with_6svs_aerosol_tables_matches_6sv() {
    let rows = compare(true);
    print_rows(&rows, &["tau_aerosol", "rho_path"]);
    let worst = |quantity: &str, keep: &dyn Fn(&Compared) -> bool| worst_of(&rows, quantity, keep);
    let nm = |r: &Compared| r.label.split(' ').nth(1).and_then(|w| w.strip_suffix("nm")).and_then(|w| w.parse().ok());
    let at = |w: f64| move |r: &Compared| nm(r) == Some(w);
    // Aerosol depth at 6SV's own wavelengths (1240, 1650, 2250 nm): the same tables, so this
    // checks the wiring (the model reaches the column, AOT(550) scales it); measured within
    // 0.01 %, the bound the tables' 7 significant digits.
    for w in [1240.0, 1650.0, 2250.0] {
        let (e, at) = worst("tau_aerosol", &at(w));
        assert!(e < 0.05, "aerosol depth at 6SV's {w} nm: {e:.3} % at {at}");
    }
    // Between 6SV's wavelengths, and over the Sentinel-2 bands: measured within 1.41 % (1375 nm,
    // between 1240 and 1536 nm; 6SV interpolates its optics across wavelength its own way).
    let (e, at) = worst("tau_aerosol", &|_| true);
    assert!(e < 1.5, "aerosol depth: {e:.2} % at {at}");
    // Path reflectance from 1240 nm and at 865 nm, both aerosol models, sea level and 1 km:
    // measured within 2.02 % (1375 nm, 1 km), where the WCP-55 models left 14 % at 1.6 µm and
    // 48 % at 2.25 µm (the test above).
    let (e, at) = worst("rho_path", &|r| nm(r).is_none_or(|w| !(900.0..1240.0).contains(&w)));
    assert!(e < 2.5, "path reflectance with 6SV's aerosol: {e:.2} % at {at}");
    // At 1020 and 1050 nm 6SV runs no radiative transfer: it interpolates its path reflectance
    // between its 860 and 1240 nm results by a power law. That law through 6SV's own 865 and
    // 1240 nm rows gives its 1020/1050 nm rows within 1 %, while the atmosphere itself (Rayleigh
    // as λ⁻⁴ beside the aerosol) is not a power law: Shoal, computing there, is up to 6.3 % lower.
    for case in ["A", "B", "C"] {
        let sixs =
            |w: f64| rows.iter().find(|r| r.quantity == "rho_path" && r.label == format!("{case} {w}nm")).unwrap();
        let (a, b) = (sixs(865.0).sixs, sixs(1240.0).sixs);
        for w in [1020.0, 1050.0] {
            let law = a * (w / 865.0_f64).powf((b / a).ln() / (1240.0_f64 / 865.0).ln());
            let r = sixs(w);
            assert!((r.sixs / law - 1.0).abs() < 0.01, "{case} {w} nm: 6SV {} against its power law {law}", r.sixs);
            assert!(r.error_pct().abs() < 7.0, "{case} {w} nm: {:.2} %", r.error_pct());
        }
    }
}

/// 6SV's models built from its component tables against its own output for the models
/// (`assets/atmosphere/aerosol_6sv_models.csv`, written by 6SV and distributed with ACOLITE):
/// the mixing rule and the tables reproduce 6SV at its 20 wavelengths.
#[test]
fn sixs_models_from_the_component_tables_are_6svs_own() {
    let t = Table::from_asset("atmosphere/aerosol_6sv_models.csv").unwrap();
    let (model, wl) = (t.column_str("model").unwrap(), t.column_f64("wavelength_nm").unwrap());
    let (ext, ssa, g) = (t.column_f64("nor_ext").unwrap(), t.column_f64("ssa").unwrap(), t.column_f64("g").unwrap());
    let (mut e_ext, mut e_ssa, mut e_g) = (0.0_f64, 0.0_f64, 0.0_f64);
    for i in 0..t.len() {
        let kind = AerosolType::parse(&format!("{}-6sv", model[i])).unwrap();
        let o = shoal::atmosphere::mixture_optics(kind, wl[i]).unwrap().unwrap();
        e_ext = e_ext.max((o.extinction_ratio - ext[i]).abs());
        e_ssa = e_ssa.max((o.ssa - ssa[i]).abs());
        e_g = e_g.max((o.phase.asymmetry() - g[i]).abs());
    }
    eprintln!("extinction {e_ext:.2e}, ssa {e_ssa:.2e}, g {e_g:.3}");
    // The file prints the extinction ratio and the albedo with 4 decimals: both within half a
    // unit of the last (measured 4.9e-5 and 4.9e-5).
    assert!(e_ext < 5.1e-5, "extinction ratio {e_ext:.2e}");
    assert!(e_ssa < 5.1e-5, "single-scattering albedo {e_ssa:.2e}");
    // 6SV's g is its Mie asymmetry parameter; Shoal's the first moment of the 83-angle phase
    // function (log-linear between the angles): measured within 0.007.
    assert!(e_g < 0.01, "asymmetry {e_g:.4}");
}

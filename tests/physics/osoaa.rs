//! The atmosphere against OSOAA V2.0 (vector, flat surface) and 6SV, on the reference rows in
//! `tests/data/osoaa` (provenance in `tests/data/PROVENANCE.md`). Shoal runs with OSOAA's own
//! Rayleigh optical depth (see `shoal::validation`), so the comparison tests the radiative
//! transfer, not the choice of Rayleigh formula.
//!
//! Tolerances are the acceptance targets: path radiance 3 % (Rayleigh only) and 5 %
//! (with aerosol), T_up 2 %, Ed(0⁺) 2 %. Because a test that passes by a wide margin does not
//! notice a regression, each quantity also has a guard a little above the accuracy measured when
//! the solver was validated (stated per assertion).

use shoal::atmosphere::{
    AIR_DEPOLARIZATION, AerosolType, RayleighDepth, RtAccuracy, WavelengthColumn, mixture_optics, solve_sun,
    solve_transmittance,
};
use shoal::spectral::Table;
use shoal::validation::{Comparison, compare_paths, compare_water_runs};

use crate::data;

fn worst(c: &[Comparison], keep: impl Fn(&Comparison) -> bool) -> (f64, String) {
    c.iter()
        .filter(|x| keep(x))
        .map(|x| (x.error_pct().abs(), format!("{} {}: shoal {:.6} osoaa {:.6}", x.case, x.quantity, x.shoal, x.osoaa)))
        .fold((0.0, String::new()), |a, b| if b.0 > a.0 { b } else { a })
}

#[test]
fn path_reflectance_and_t_down_match_osoaa_vector() {
    let c = compare_paths(&RtAccuracy::default()).unwrap();
    assert_eq!(c.len(), 2 * 95, "every reference row is compared");
    let (e, case) = worst(&c, |x| x.quantity == "rho_path" && x.aerosol == AerosolType::None);
    assert!(e < 3.0, "Rayleigh path radiance target 3 %: {e:.2} % at {case}");
    // Guard: 0.92 % measured (scalar SOS + vector Rayleigh correction).
    assert!(e < 1.3, "Rayleigh path radiance regressed: {e:.2} % at {case}");
    let (e, case) = worst(&c, |x| x.quantity == "rho_path" && x.aerosol != AerosolType::None);
    assert!(e < 5.0, "aerosol path radiance target 5 %: {e:.2} % at {case}");
    // Guard: 1.15 % measured.
    assert!(e < 1.5, "aerosol path radiance regressed: {e:.2} % at {case}");
    let (e, case) = worst(&c, |x| x.quantity == "t_down");
    assert!(e < 2.0, "Ed(0+) target 2 %: {e:.2} % at {case}");
    // Guard: 0.91 % measured.
    assert!(e < 1.3, "t_down regressed: {e:.2} % at {case}");
}

#[test]
fn water_runs_match_osoaa_ed_and_heron_t_up() {
    let c = compare_water_runs(&RtAccuracy::default()).unwrap();
    let (e, case) = worst(&c, |x| x.quantity == "ed_0plus");
    assert!(e < 2.0, "coupled Ed(0+) target 2 %: {e:.2} % at {case}");
    // Guard: 0.70 % measured.
    assert!(e < 1.2, "coupled Ed(0+) regressed: {e:.2} % at {case}");
    // T_up_eff = (L_toa − L_path)/Lw is a small difference of large numbers where the water is
    // dark; OSOAA stops its orders at 0.1 % of the radiance, so where Lw < 10 % of L_toa its
    // T_up_eff is uncertain by more than 1 % and is not used.
    let usable = |x: &Comparison| x.quantity == "t_up" && x.lw_fraction.unwrap_or(0.0) >= 0.1;
    let (e, case) = worst(&c, |x| usable(x) && x.case.starts_with("heron"));
    assert!(e < 2.0, "T_up target 2 %: {e:.2} % at {case}");
    // Guard: 1.20 % measured.
    assert!(e < 1.5, "T_up regressed: {e:.2} % at {case}");
}

#[test]
fn hume_t_up_differs_only_by_the_waters_bidirectional_shape() {
    // OSOAA's Lake Hume run (turbid water, sun at 60°) has an upwelling radiance that is brighter
    // away from nadir than at nadir, so its T_up_eff — which divides all transmitted water light
    // by the nadir Lw — exceeds the transmittance of an isotropic in-water field's Lw. Shoal's
    // water model has no bidirectional shape, so its T_up is that field's. The signature is a
    // near-constant ratio of the diffuse parts at every wavelength (1.14–1.19, mean 1.17; the
    // spread follows OSOAA's own convergence noise, largest where Lw is smallest), with direct
    // parts that agree exactly; an atmospheric error would not be a constant factor.
    let t = Table::from_file(&data("osoaa/water_ref.csv")).unwrap();
    let (scenario, rt, wind) =
        (t.column_str("scenario").unwrap(), t.column_str("rt").unwrap(), t.column_f64("wind").unwrap());
    let (wl, tau_r) = (t.column_f64("wl_nm").unwrap(), t.column_f64("tau_ray").unwrap());
    let (t_up_eff, t_dir) = (t.column_f64("T_up_eff").unwrap(), t.column_f64("T_dir_up").unwrap());
    let (lw, l_toa) = (t.column_f64("Lw").unwrap(), t.column_f64("L_toa").unwrap());
    let mut ratios = Vec::new();
    for i in (0..t.len()).filter(|&i| scenario[i] == "hume" && rt[i] == "vector" && wind[i] == 0.0) {
        let aerosol = mixture_optics(AerosolType::Continental, wl[i])
            .unwrap()
            .map(|o| (0.1 * o.extinction_ratio, o.ssa, o.phase));
        let col = WavelengthColumn {
            wavelength_nm: wl[i],
            tau_rayleigh: tau_r[i],
            depolarization: AIR_DEPOLARIZATION,
            aerosol,
            rayleigh_scale_height_km: 8.0,
            aerosol_scale_height_km: 2.0,
            water_index: 1.34,
        };
        let up = solve_transmittance(&col, &[1.0], &RtAccuracy::default());
        assert!(
            (up.t_up_direct[0] / t_dir[i] - 1.0).abs() < 2e-4,
            "{} nm direct: {} vs {}",
            wl[i],
            up.t_up_direct[0],
            t_dir[i]
        );
        if lw[i] / l_toa[i] >= 0.1 {
            ratios.push((t_up_eff[i] - t_dir[i]) / (up.t_up[0] - up.t_up_direct[0]));
        }
    }
    assert!(ratios.len() >= 12);
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    let spread = ratios.iter().fold(0.0f64, |m, r| m.max((r - mean).abs()));
    assert!((1.12..1.22).contains(&mean) && spread < 0.04, "diffuse-part ratios {ratios:?}");
}

#[test]
fn t_up_matches_6s_for_a_uniform_water_leaving_radiance() {
    // 6SV's upward transmittance assumes a uniform (Lambertian) source over a black surface;
    // Shoal's source is an isotropic in-water field (within 0.1 % of uniform above water below
    // 50°) over the Fresnel surface. With 6S's own optical depths the two agree to the
    // difference of those choices and of the aerosol phase functions (6S's continental model vs
    // the OSOAA/WMO Mie mixture): 0.46 % measured.
    let t = Table::from_file(&data("osoaa/path_compare.csv")).unwrap();
    let (wl, sza, vza) = (t.column_f64("wl_nm").unwrap(), t.column_f64("sza").unwrap(), t.column_f64("vza").unwrap());
    let aer = t.column_str("aer").unwrap();
    let (tr, ta, tup) =
        (t.column_f64("tau_ray_6s").unwrap(), t.column_f64("tau_aer_6s").unwrap(), t.column_f64("tS_up_6s").unwrap());
    for i in (0..t.len()).filter(|&i| sza[i] == 60.0) {
        let kind = AerosolType::parse(aer[i]).unwrap();
        let aerosol = mixture_optics(kind, wl[i]).unwrap().map(|o| (ta[i], o.ssa, o.phase));
        let col = WavelengthColumn {
            wavelength_nm: wl[i],
            tau_rayleigh: tr[i],
            depolarization: AIR_DEPOLARIZATION,
            aerosol,
            rayleigh_scale_height_km: 8.0,
            aerosol_scale_height_km: 2.0,
            water_index: 1.34,
        };
        let muv = vza[i].to_radians().cos();
        let up = solve_transmittance(&col, &[muv], &RtAccuracy::default());
        let e = 100.0 * (up.t_up[0] / tup[i] - 1.0);
        assert!(e.abs() < 0.8, "{} nm vza {} {}: {e:.2} %", wl[i], vza[i], aer[i]);
    }
}

#[test]
fn osoaa_rayleigh_depth_is_below_bodhaine_as_documented() {
    // The reference README: Hansen–Travis-type depths are 1.5–3 % below Bodhaine et al. (1999).
    let t = Table::from_file(&data("osoaa/path_compare.csv")).unwrap();
    let wl = t.column_f64("wl_nm").unwrap();
    for w in wl {
        let site = Default::default();
        let ratio = RayleighDepth::OsoaaHansenTravis.tau(w, &site) / RayleighDepth::Bodhaine.tau(w, &site);
        assert!((0.965..0.99).contains(&ratio), "{w} nm: {ratio}");
    }
    // And the path radiance moves with it: the blue path reflectance with Bodhaine's depth is
    // larger by roughly the depth ratio.
    let acc = RtAccuracy::default();
    let ray = |tau| WavelengthColumn {
        wavelength_nm: 400.0,
        tau_rayleigh: tau,
        depolarization: AIR_DEPOLARIZATION,
        aerosol: None,
        rayleigh_scale_height_km: 8.0,
        aerosol_scale_height_km: 2.0,
        water_index: 1.34,
    };
    let site = Default::default();
    let a = solve_sun(&ray(RayleighDepth::OsoaaHansenTravis.tau(400.0, &site)), 0.5, &[1.0], &acc).radiance(0, 1.5);
    let b = solve_sun(&ray(RayleighDepth::Bodhaine.tau(400.0, &site)), 0.5, &[1.0], &acc).radiance(0, 1.5);
    assert!(b / a > 1.015 && b / a < 1.03, "{}", b / a);
}

#[test]
fn polarised_radiance_at_the_top_matches_osoaa_where_molecules_polarise() {
    // OSOAA's TOA degree of linear polarisation times its radiance against the path's √(Q² + U²)
    // from Shoal's vector solution. Shoal's molecules polarise and its aerosol does not (the
    // vector solution treats it as a depolarising scatterer; `atmosphere::rt`), so the two
    // agree where molecules dominate the path and part as the aerosol's share grows: the
    // polarisation effect of an instrument is right in the blue and low in the NIR.
    let c = shoal::validation::compare_polarisation(&RtAccuracy::default()).unwrap();
    assert_eq!(c.len(), 38, "every flat-surface vector row is compared");
    let (e, case) = worst(&c, |x| x.wavelength_nm <= 443.0);
    // Measured: 19.0 % at Heron 443 nm (maritime aerosol), 9.2 % at Lake Hume.
    assert!(e < 20.0, "polarised radiance at 400–443 nm: {e:.1} % at {case}");
    // The NIR: the aerosol's own polarisation is missing, so Shoal is low, never high (measured
    // −40 to −82 % at 865–897 nm).
    for x in c.iter().filter(|x| x.wavelength_nm > 443.0) {
        assert!(x.shoal < x.osoaa && x.shoal > 0.15 * x.osoaa, "{}: {} vs {}", x.case, x.shoal, x.osoaa);
    }
}

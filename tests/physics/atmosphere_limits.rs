//! Limits, determinism and bad input for the atmosphere.

use shoal::atmosphere::{AerosolType, AtmosphereLut, AtmosphereSpec, Geometry, LutAxes, RtAccuracy, SeaSurface};

fn spec(aerosol: AerosolType, aot550: f64) -> AtmosphereSpec {
    AtmosphereSpec { aerosol, aot550, ..Default::default() }
}

#[test]
fn zero_aot_is_the_rayleigh_atmosphere() {
    let g = Geometry::from_degrees(40.0, 20.0, 120.0);
    let a = spec(AerosolType::Continental, 0.0).build().unwrap().terms(500.0, &g).unwrap();
    let b = spec(AerosolType::None, 0.1).build().unwrap().terms(500.0, &g).unwrap();
    assert_eq!(a.l_path_w_m2_sr_nm, b.l_path_w_m2_sr_nm);
    assert_eq!(a.tau_aerosol, 0.0);
}

#[test]
fn thin_atmosphere_tends_to_single_scattering() {
    // At 1000 nm (τ_R ≈ 0.009) multiple scattering adds only a few per cent to the path
    // radiance; the single-scattering mode must be within that and below the full solution.
    let g = Geometry::from_degrees(30.0, 10.0, 90.0);
    let full = spec(AerosolType::None, 0.0).build().unwrap().terms(1000.0, &g).unwrap();
    let single = AtmosphereSpec { accuracy: RtAccuracy::preset("single").unwrap(), ..spec(AerosolType::None, 0.0) }
        .build()
        .unwrap()
        .terms(1000.0, &g)
        .unwrap();
    let ratio = single.l_path_w_m2_sr_nm / full.l_path_w_m2_sr_nm;
    assert!(ratio > 0.93 && ratio < 1.0, "{ratio}");
}

#[test]
fn transmittances_and_albedo_are_physical() {
    for aerosol in [AerosolType::None, AerosolType::Maritime, AerosolType::Continental, AerosolType::Urban] {
        for aot in [0.0, 0.3, 1.0, 5.0] {
            let atm = spec(aerosol, aot).build().unwrap();
            // Away from the flat sea's mirror direction (see the next test), to the limits.
            for (sza, vza) in [(10.0, 0.0), (60.0, 40.0), (85.0, 60.0), (89.0, 85.0)] {
                let t = atm.terms(443.0, &Geometry::from_degrees(sza, vza, 45.0)).unwrap();
                for (name, v) in
                    [("t_up", t.t_up), ("t_down", t.t_down), ("S", t.spherical_albedo), ("t_up_direct", t.t_up_direct)]
                {
                    assert!(v.is_finite() && (0.0..=1.0).contains(&v), "{aerosol:?} {aot} {sza}/{vza}: {name} = {v}");
                }
                assert!(t.t_up >= t.t_up_direct, "{aerosol:?} {aot} {sza}/{vza}: {} < {}", t.t_up, t.t_up_direct);
                // Path radiance is positive and finite; ρ = πL/(E₀μ₀) stays below 1 except at
                // grazing geometry, where it legitimately exceeds 1 (a slant path of 11 air
                // masses under a sun at 89°, normalised by the tiny horizontal irradiance).
                assert!(t.l_path_w_m2_sr_nm > 0.0 && t.l_path_w_m2_sr_nm.is_finite(), "{aerosol:?} {aot} {sza}/{vza}");
                if sza < 80.0 {
                    assert!(t.rho_path < 1.0, "{aerosol:?} {aot} {sza}/{vza}: ρ = {}", t.rho_path);
                }
            }
        }
    }
}

#[test]
fn the_flat_sea_mirrors_the_aureole() {
    // Sun overhead, nadir view: light scattered forward by aerosols (Θ ≈ 0°) is reflected
    // specularly by a flat sea into the sensor, so the path reflectance there far exceeds a
    // typical 0.1 (a rough sea smears this over the glint pattern). It must be large and finite.
    let t =
        spec(AerosolType::Maritime, 0.3).build().unwrap().terms(443.0, &Geometry::from_degrees(0.0, 0.0, 0.0)).unwrap();
    assert!(t.rho_path.is_finite() && t.rho_path > 0.5, "{}", t.rho_path);
    let off = spec(AerosolType::Maritime, 0.3)
        .build()
        .unwrap()
        .terms(443.0, &Geometry::from_degrees(10.0, 0.0, 0.0))
        .unwrap();
    assert!(off.rho_path < 0.4, "{}", off.rho_path);
}

#[test]
fn lut_interpolation_agrees_with_direct_solves() {
    let atm = spec(AerosolType::Maritime, 0.15).build().unwrap();
    let axes = LutAxes::covering(vec![443.0, 865.0], (20.0, 40.0), 40.0, (5.0, 5.0, 10.0));
    let lut = AtmosphereLut::build(&atm, axes).unwrap();
    // Off every node.
    let g = Geometry::from_degrees(27.3, 17.9, 133.0);
    for (w, wl) in [443.0, 865.0].iter().enumerate() {
        let d = atm.terms(*wl, &g).unwrap();
        let l = lut.terms(w, &g).unwrap();
        // Bilinear interpolation of smooth coefficients on 5° zenith nodes, exact in azimuth.
        for (name, a, b) in [
            ("l_path", l.l_path_w_m2_sr_nm, d.l_path_w_m2_sr_nm),
            ("t_up", l.t_up, d.t_up),
            ("ed", l.ed_0plus_w_m2_nm, d.ed_0plus_w_m2_nm),
        ] {
            assert!((a / b - 1.0).abs() < 3e-3, "{wl} nm {name}: LUT {a} vs direct {b}");
        }
    }
}

#[test]
fn irradiance_does_not_depend_on_the_number_of_streams() {
    // Delta-M moves the truncated forward peak into the direct beam; the total Ed(0+) must
    // then be the same whatever the truncation order (6, 12, 24 streams): 0.3 % spread allowed
    // for the quadrature of the diffuse part.
    for (aerosol, aot, sza) in
        [(AerosolType::Maritime, 0.3, 60.0), (AerosolType::Continental, 1.0, 30.0), (AerosolType::Urban, 0.5, 75.0)]
    {
        let t = |streams| {
            let acc = RtAccuracy { streams, fourier_terms: 2 * streams, ..RtAccuracy::default() };
            AtmosphereSpec { accuracy: acc, ..spec(aerosol, aot) }
                .build()
                .unwrap()
                .terms(443.0, &Geometry::from_degrees(sza, 0.0, 0.0))
                .unwrap()
                .t_down
        };
        let (a, b, c) = (t(6), t(12), t(24));
        assert!((a / c - 1.0).abs() < 3e-3 && (b / c - 1.0).abs() < 3e-3, "{aerosol:?}: {a} {b} {c}");
    }
}

#[test]
fn low_sun_converges_with_layer_thickness() {
    // The first-order source e^{−τ/μ₀} is integrated exactly within layers, so even at 89°
    // (μ₀ = 0.017, e-folding in 0.017 of optical depth) the default 0.02 layers are within
    // 0.3 % of 0.001 layers.
    for (aerosol, aot) in [(AerosolType::None, 0.0), (AerosolType::Continental, 0.3)] {
        let run = |dtau| {
            let acc = RtAccuracy { max_layer_depth: dtau, min_layers: 1, ..RtAccuracy::default() };
            AtmosphereSpec { accuracy: acc, ..spec(aerosol, aot) }
                .build()
                .unwrap()
                .terms(400.0, &Geometry::from_degrees(89.0, 30.0, 90.0))
                .unwrap()
        };
        let (coarse, fine) = (run(0.02), run(0.001));
        assert!((coarse.t_down / fine.t_down - 1.0).abs() < 3e-3, "{aerosol:?}: {} vs {}", coarse.t_down, fine.t_down);
        assert!(
            (coarse.rho_path / fine.rho_path - 1.0).abs() < 3e-3,
            "{aerosol:?}: {} vs {}",
            coarse.rho_path,
            fine.rho_path
        );
    }
}

#[test]
fn lut_refuses_geometry_outside_its_nodes() {
    let atm = spec(AerosolType::Maritime, 0.1).build().unwrap();
    let lut = AtmosphereLut::build(&atm, LutAxes::covering(vec![550.0], (30.0, 30.0), 10.0, (5.0, 5.0, 10.0))).unwrap();
    assert!(lut.terms(0, &Geometry::from_degrees(30.0, 8.0, 0.0)).is_ok());
    let e = lut.terms(0, &Geometry::from_degrees(60.0, 8.0, 0.0)).unwrap_err().to_string();
    assert!(e.contains("sun_zenith") && e.contains("30"), "{e}");
    let e = lut.terms(0, &Geometry::from_degrees(30.0, 40.0, 0.0)).unwrap_err().to_string();
    assert!(e.contains("view_zenith"), "{e}");
    assert!(lut.terms(3, &Geometry::from_degrees(30.0, 8.0, 0.0)).is_err());
}

#[test]
fn lut_is_identical_on_one_and_two_threads() {
    let atm = spec(AerosolType::Continental, 0.1).build().unwrap();
    let axes = LutAxes::covering(vec![412.0, 560.0, 865.0], (30.0, 50.0), 30.0, (10.0, 10.0, 30.0));
    let build = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| AtmosphereLut::build(&atm, axes.clone()).unwrap())
    };
    let (one, two) = (build(1), build(2));
    let g = Geometry::from_degrees(41.0, 12.0, 77.0);
    for w in 0..3 {
        let (a, b) = (one.terms(w, &g).unwrap(), two.terms(w, &g).unwrap());
        assert_eq!(a.l_path_w_m2_sr_nm.to_bits(), b.l_path_w_m2_sr_nm.to_bits());
        assert_eq!(a.t_up.to_bits(), b.t_up.to_bits());
        assert_eq!(a.ed_0plus_w_m2_nm.to_bits(), b.ed_0plus_w_m2_nm.to_bits());
    }
}

#[test]
fn glint_matches_osoaa_rough_surface() {
    // OSOAA's wind-5-minus-flat path reflectance (sun 20°, Rayleigh atmosphere) is the sun glint
    // plus the smaller change in reflected sky light. Cox–Munk glint times the direct
    // transmittances must reproduce it where glint dominates (nadir: 0.068 at 865 nm); 3 %
    // allows for the rough-surface sky term Shoal does not model.
    let t = shoal::spectral::Table::from_file(&crate::data("osoaa/path_compare.csv")).unwrap();
    let (wl, sza, vza) = (t.column_f64("wl_nm").unwrap(), t.column_f64("sza").unwrap(), t.column_f64("vza").unwrap());
    let aer = t.column_str("aer").unwrap();
    let diff = t.column_f64("glint_plus_rough_ws5_minus_flat").unwrap();
    let atm = AtmosphereSpec {
        surface: SeaSurface::Wind { speed_m_s: 5.0 },
        rayleigh: shoal::atmosphere::RayleighDepth::OsoaaHansenTravis,
        ..spec(AerosolType::None, 0.0)
    }
    .build()
    .unwrap();
    let mut checked = 0;
    for i in (0..t.len()).filter(|&i| sza[i] == 20.0 && aer[i] == "none" && wl[i] > 600.0) {
        let g = Geometry::from_degrees(sza[i], vza[i], 90.0);
        let terms = atm.terms(wl[i], &g).unwrap();
        let rho_glint = std::f64::consts::PI * terms.l_glint_w_m2_sr_nm / (terms.e0_w_m2_nm * 20f64.to_radians().cos());
        let e = rho_glint / diff[i] - 1.0;
        assert!(e.abs() < 0.03, "{} nm vza {}: glint {rho_glint:.5} vs OSOAA {:.5}", wl[i], vza[i], diff[i]);
        checked += 1;
    }
    assert!(checked >= 20);
    let flat = spec(AerosolType::Maritime, 0.1).build().unwrap();
    assert_eq!(flat.terms(865.0, &Geometry::from_degrees(20.0, 20.0, 180.0)).unwrap().l_glint_w_m2_sr_nm, 0.0);
}

#[test]
fn gases_absorb_where_they_should() {
    let g = Geometry::from_degrees(30.0, 0.0, 90.0);
    let on = AtmosphereSpec { gases: true, ..spec(AerosolType::Maritime, 0.1) }.build().unwrap();
    let off = spec(AerosolType::Maritime, 0.1).build().unwrap();
    let a_band = on.terms(761.0, &g).unwrap().t_gas;
    let blue = on.terms(412.0, &g).unwrap().t_gas;
    assert!(a_band < 0.5 && blue > 0.99, "{a_band} {blue}");
    assert_eq!(off.terms(761.0, &g).unwrap().t_gas, 1.0);
}

#[test]
fn bad_inputs_name_the_field_and_range() {
    let cases: Vec<(AtmosphereSpec, &str)> = vec![
        (spec(AerosolType::Maritime, -0.1), "aot550"),
        (spec(AerosolType::Maritime, f64::NAN), "aot550"),
        (AtmosphereSpec { pressure_hpa: 20.0, ..Default::default() }, "pressure_hpa"),
        (
            AtmosphereSpec { surface: SeaSurface::Wind { speed_m_s: 80.0 }, ..Default::default() },
            "surface.Wind.speed_m_s",
        ),
        (AtmosphereSpec { accuracy: RtAccuracy { streams: 0, ..Default::default() }, ..Default::default() }, "streams"),
        (AtmosphereSpec { day_of_year: 0, ..Default::default() }, "day_of_year"),
    ];
    for (s, field) in cases {
        let e = s.build().unwrap_err().to_string();
        assert!(e.contains(field) && e.contains("allowed"), "{e}");
    }
    let atm = AtmosphereSpec::default().build().unwrap();
    for (g, field) in [
        (Geometry::from_degrees(90.0, 0.0, 0.0), "sun_zenith"),
        (Geometry::from_degrees(30.0, 88.0, 0.0), "view_zenith"),
        (Geometry::from_degrees(f64::NAN, 0.0, 0.0), "sun_zenith"),
    ] {
        let e = atm.terms(500.0, &g).unwrap_err().to_string();
        assert!(e.contains(field), "{e}");
    }
    let e = atm.terms(200.0, &Geometry::from_degrees(30.0, 0.0, 0.0)).unwrap_err().to_string();
    assert!(e.contains("wavelength"), "{e}");
}

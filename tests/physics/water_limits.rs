//! Limit and bad-input tests of the water model: optically deep, zero constituents, the
//! SAMBUCA defaults on the product grid, and refusals that name the field.

use shoal::spectral::WavelengthGrid;
use shoal::water::{Bottom, SiopSpec, SubstrateLibrary, SubstrateMix, WaterColumn, WaterGeometry, WaterModel};

fn model() -> WaterModel {
    let grid = WavelengthGrid::uniform(350.0, 900.0, 1.0).unwrap();
    WaterModel::new(SiopSpec::sambuca_default().resolve(&grid, None).unwrap())
}

#[test]
fn deep_limit_equals_the_deep_formula() {
    // As H → ∞ the shallow model must tend to rrs_dp (Lee 1998 eq. 2 with the bottom term gone).
    let m = model();
    let lib = SubstrateLibrary::embedded().unwrap();
    let rb = lib.mix_on_grid(&SubstrateMix::parse("sand").unwrap(), &m.siop().grid).unwrap();
    let geo = WaterGeometry::from_degrees(30.0, 0.0);
    let c = |bottom| WaterColumn { chl_mg_m3: 2.0, cdom_per_m: 0.1, nap_g_m3: 3.0, bottom };
    let deep = m.evaluate(&c(Bottom::OpticallyDeep), &geo).unwrap();
    let far = m.evaluate(&c(Bottom::Shallow { depth_m: 5000.0, reflectance: &rb }), &geo).unwrap();
    for (d, f) in deep.rrs.iter().zip(&far.rrs) {
        assert!((d - f).abs() <= 1e-15, "{d} vs {f}");
    }
    assert!(deep.r_substratum.is_empty(), "deep water never evaluates the bottom");
}

#[test]
fn zero_depth_limit_is_the_bottom_over_pi() {
    // At H → 0: rrs → ρ_b/π (Lee 1998 eq. 2).
    let m = model();
    let rb = vec![0.3; m.siop().grid.len()];
    let col = WaterColumn {
        chl_mg_m3: 1.0,
        cdom_per_m: 0.05,
        nap_g_m3: 1.0,
        bottom: Bottom::Shallow { depth_m: 1e-9, reflectance: &rb },
    };
    let r = m.evaluate(&col, &WaterGeometry::from_degrees(20.0, 0.0)).unwrap();
    for v in &r.rrs {
        assert!((v - 0.3 / std::f64::consts::PI).abs() < 1e-8, "{v}");
    }
}

#[test]
fn pure_water_has_only_water_terms() {
    let m = model();
    let col = WaterColumn { chl_mg_m3: 0.0, cdom_per_m: 0.0, nap_g_m3: 0.0, bottom: Bottom::OpticallyDeep };
    let r = m.evaluate(&col, &WaterGeometry::from_degrees(30.0, 0.0)).unwrap();
    assert_eq!(r.a, r.a_w);
    assert_eq!(r.bb, r.bb_w);
    assert!(r.rrs_above.iter().all(|v| v.is_finite() && *v > 0.0 && *v < 1.0 / std::f64::consts::PI));
}

#[test]
fn bad_inputs_are_refused_naming_the_field() {
    let m = model();
    let geo = WaterGeometry::from_degrees(30.0, 0.0);
    let rb = vec![0.2; m.siop().grid.len()];
    let cases = [
        (WaterColumn { chl_mg_m3: -1.0, cdom_per_m: 0.0, nap_g_m3: 0.0, bottom: Bottom::OpticallyDeep }, "chl"),
        (WaterColumn { chl_mg_m3: 1.0, cdom_per_m: f64::NAN, nap_g_m3: 0.0, bottom: Bottom::OpticallyDeep }, "cdom"),
        (WaterColumn { chl_mg_m3: 1.0, cdom_per_m: 0.0, nap_g_m3: -2.0, bottom: Bottom::OpticallyDeep }, "nap"),
        (
            WaterColumn {
                chl_mg_m3: 1.0,
                cdom_per_m: 0.0,
                nap_g_m3: 0.0,
                bottom: Bottom::Shallow { depth_m: 0.0, reflectance: &rb },
            },
            "depth",
        ),
    ];
    for (col, field) in cases {
        let e = m.evaluate(&col, &geo).unwrap_err().to_string();
        assert!(e.contains(field) && e.contains("allowed"), "{e}");
    }
    let ok = WaterColumn { chl_mg_m3: 1.0, cdom_per_m: 0.0, nap_g_m3: 0.0, bottom: Bottom::OpticallyDeep };
    let e = m.evaluate(&ok, &WaterGeometry::from_degrees(90.0, 0.0)).unwrap_err().to_string();
    assert!(e.contains("sun_zenith"), "{e}");
    let e = SubstrateLibrary::embedded().unwrap().get("basalt").unwrap_err().to_string();
    assert!(e.contains("basalt") && e.contains("sand"), "{e}");
}

#[test]
fn sambuca_defaults_do_not_cover_the_full_fine_grid() {
    // SAMBUCA's a_w stops at 900 nm: asking for 1000 nm must say so, not extrapolate silently.
    let e = SiopSpec::sambuca_default().resolve(&WavelengthGrid::fine(), None).unwrap_err().to_string();
    assert!(e.contains("water_absorption") && e.contains("350–900 nm") && e.contains("901 nm"), "{e}");
}

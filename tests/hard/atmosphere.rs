//! The atmosphere at its extremes: no aerosol and AOT 1, every aerosol type, sun from overhead to
//! 85°, view to 60° (beyond the widest swath edge of the presets), blue to near infrared.

use shoal::atmosphere::{AerosolType, AtmosphereSpec, Geometry};

#[test]
fn transmittances_stay_fractions_and_radiances_finite() {
    let mut cases = 0;
    for aerosol in [AerosolType::None, AerosolType::Maritime, AerosolType::Continental, AerosolType::Urban] {
        for aot550 in [0.0, 1.0] {
            if aerosol == AerosolType::None && aot550 > 0.0 {
                continue;
            }
            let atm = AtmosphereSpec { aerosol, aot550, ..AtmosphereSpec::default() }.build().unwrap();
            for sun in [0.0, 30.0, 60.0, 85.0] {
                for view in [0.0, 30.0, 60.0] {
                    for nm in [400.0, 560.0, 865.0] {
                        let case = format!("{aerosol:?} AOT {aot550}, sun {sun}, view {view}, {nm} nm");
                        let t = atm.terms(nm, &Geometry::from_degrees(sun, view, 90.0)).unwrap();
                        for (name, v) in [
                            ("t_up", t.t_up),
                            ("t_down", t.t_down),
                            ("t_up_direct", t.t_up_direct),
                            ("t_down_direct", t.t_down_direct),
                            ("t_gas", t.t_gas),
                            ("spherical albedo", t.spherical_albedo),
                        ] {
                            assert!(v.is_finite() && (0.0..=1.0).contains(&v), "{case}: {name} = {v}");
                        }
                        assert!(t.t_up_direct <= t.t_up, "{case}: direct above total");
                        assert!(t.l_path_w_m2_sr_nm.is_finite() && t.l_path_w_m2_sr_nm > 0.0, "{case}: path radiance");
                        assert!(t.tau_aerosol.is_finite() && t.tau_aerosol >= 0.0, "{case}: τ_a");
                        if aot550 == 0.0 {
                            assert_eq!(t.tau_aerosol, 0.0, "{case}");
                        }
                        cases += 1;
                    }
                }
            }
        }
    }
    assert_eq!(cases, 7 * 4 * 3 * 3);
    eprintln!("atmosphere: {cases} cases");
}

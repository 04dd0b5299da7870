//! An aerosol from a user's own log-normal size distribution (`AerosolType::LogNormal`): the
//! Mie code over the user's modes, limit tests against the WMO component table, the spectral
//! behaviour fine and coarse particles must show, and bad input named.

use shoal::atmosphere::{
    AerosolMode, AerosolType, AtmosphereSpec, Component, ComponentTable, SizeDistribution, mixture_optics,
    table_angles_deg,
};

/// The WMO oceanic component's distribution (r_m 0.3 µm, σ_g 10^0.39967) with its 550 nm
/// refractive index.
fn oceanic_like() -> AerosolMode {
    AerosolMode { mode_radius_um: 0.3, sigma_g: 10f64.powf(0.39967), refractive_real: 1.381, refractive_imag: 0.0 }
}

#[test]
fn a_mode_with_a_wmo_components_distribution_has_its_optics() {
    let mu: Vec<f64> = table_angles_deg().iter().map(|a| a.to_radians().cos()).collect();
    let user = oceanic_like().compute(550.0, &mu);
    let wmo = ComponentTable::embedded().unwrap().component_at(Component::Oceanic, 550.0).unwrap();
    let ext = user.c_ext_um2 / wmo.c_ext_um2 - 1.0;
    let sca = user.c_sca_um2 / wmo.c_sca_um2 - 1.0;
    let angles = table_angles_deg();
    let worst = |from: f64, to: f64| {
        let pairs = user.p11.iter().zip(&wmo.p11).zip(&angles).filter(|(_, a)| (from..to).contains(*a));
        pairs.map(|((u, w), _)| (u / w - 1.0).abs()).fold(0.0, f64::max)
    };
    let (spike, rest) = (worst(0.0, 0.5), worst(0.5, 181.0));
    println!(
        "oceanic-like mode at 550 nm: C_ext {ext:+.2e}, C_sca {sca:+.2e}, P11 below 0.5° {spike:.2e}, beyond {rest:.2e}"
    );
    // Same Mie code and size grid; the user mode stops at r = 30 µm where the WMO component
    // goes on to α = 800 (r = 70 µm). Particles beyond 30 µm carry ~1e-3 of the cross-section
    // (3.2 σ past the median of the area-weighted distribution): measured −6.4e-4, bound 2e-3.
    // They make the diffraction spike within 0.5° of forward (measured up to −7.4 %, bound
    // 10 %), a cone no satellite view resolves; beyond it P₁₁ agrees to 1.2e-3 (bound 2e-3).
    assert!(ext.abs() < 2e-3 && sca.abs() < 2e-3, "{ext} {sca}");
    assert!(spike < 0.1 && rest < 2e-3, "{spike} {rest}");
}

#[test]
fn a_coarse_mode_of_no_volume_leaves_the_fine_mode_alone() {
    let fine = AerosolMode { mode_radius_um: 0.08, sigma_g: 1.6, refractive_real: 1.45, refractive_imag: 0.005 };
    let coarse = AerosolMode { mode_radius_um: 0.8, sigma_g: 1.8, refractive_real: 1.38, refractive_imag: 0.0 };
    let alone = AerosolType::LogNormal(SizeDistribution { fine, coarse: None, coarse_volume_fraction: 0.0 });
    let none = AerosolType::LogNormal(SizeDistribution { fine, coarse: Some(coarse), coarse_volume_fraction: 0.0 });
    let half = AerosolType::LogNormal(SizeDistribution { fine, coarse: Some(coarse), coarse_volume_fraction: 0.5 });
    let tau_ratio = |kind: AerosolType, nm: f64| mixture_optics(kind, nm).unwrap().unwrap().extinction_ratio;
    for nm in [443.0, 865.0] {
        assert_eq!(tau_ratio(alone, nm), tau_ratio(none, nm));
    }
    // Ångström exponents 443–865 nm: fine particles scatter much more in the blue, a coarse
    // mode flattens the spectrum (AERONET's fine-mode α ≈ 1.5–2.5, coarse ≈ 0–0.5).
    let angstrom =
        |kind: AerosolType| -(tau_ratio(kind, 865.0) / tau_ratio(kind, 443.0)).ln() / (865.0f64 / 443.0).ln();
    let only_coarse =
        AerosolType::LogNormal(SizeDistribution { fine: coarse, coarse: None, coarse_volume_fraction: 0.0 });
    let (a_fine, a_half, a_coarse) = (angstrom(alone), angstrom(half), angstrom(only_coarse));
    println!("Ångström: fine {a_fine:.2}, half coarse by volume {a_half:.2}, coarse {a_coarse:.2}");
    assert!(a_fine > 1.5 && a_fine < 2.6, "{a_fine}");
    assert!(a_coarse > -0.3 && a_coarse < 0.5, "{a_coarse}");
    assert!(a_half > a_coarse && a_half < a_fine, "{a_half}");
    // An absorbing fine mode has ω < 1; a non-absorbing coarse one ω = 1.
    let ssa = |kind: AerosolType| mixture_optics(kind, 550.0).unwrap().unwrap().ssa;
    assert!(ssa(alone) < 0.99 && (ssa(only_coarse) - 1.0).abs() < 1e-12, "{} {}", ssa(alone), ssa(only_coarse));
}

#[test]
fn a_size_distribution_out_of_range_names_its_field() {
    let mut spec = AtmosphereSpec {
        aerosol: AerosolType::LogNormal(SizeDistribution {
            fine: AerosolMode { sigma_g: 0.9, ..oceanic_like() },
            coarse: None,
            coarse_volume_fraction: 0.0,
        }),
        ..AtmosphereSpec::default()
    };
    let e = spec.validate().unwrap_err().to_string();
    assert!(e.contains("aerosol.LogNormal.fine.sigma_g") && e.contains("1.05 to 2.6"), "{e}");
    spec.aerosol = AerosolType::LogNormal(SizeDistribution {
        fine: oceanic_like(),
        coarse: Some(AerosolMode { refractive_imag: -0.1, ..oceanic_like() }),
        coarse_volume_fraction: 0.3,
    });
    let e = spec.validate().unwrap_err().to_string();
    assert!(e.contains("aerosol.LogNormal.coarse.refractive_imag"), "{e}");
    let parsed = AerosolType::parse("lognormal:0.3,2.51,1.381,0").unwrap();
    assert!(matches!(parsed, AerosolType::LogNormal(d) if d.coarse.is_none() && d.fine.mode_radius_um == 0.3));
    assert!(AerosolType::parse("lognormal:0.3,2.51").unwrap_err().contains("2 numbers"));
}

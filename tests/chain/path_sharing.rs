//! The atmosphere on the grid, shared between atmospheres: the gas factors of a geometry,
//! computed once for every atmosphere with the same gases (the image-based correction's family),
//! give each atmosphere, bit for bit, the spectrum and band terms it computes alone.

use std::sync::Arc;

use shoal::atmosphere::{AerosolType, AtmosphereLut, AtmosphereSpec, Geometry, LutAxes};
use shoal::instrument::band_atmosphere::{band_terms, band_terms_of_each};
use shoal::instrument::{InstrumentSpec, Response, Viewing};
use shoal::scene::Scene;
use shoal::spectral::WavelengthGrid;
use shoal::toa::{PathOptics, SceneOptics};

use super::small_lake;

/// The LUT of `spec`: nodes 40 nm apart over 380–940 nm, sun zenith 20–60°, view zenith to 30°..
fn lut(spec: &AtmosphereSpec) -> Arc<AtmosphereLut> {
    let atm = spec.build().unwrap();
    let nodes: Vec<f64> = (0..=14).map(|k| 380.0 + 40.0 * f64::from(k)).collect();
    Arc::new(AtmosphereLut::build(&atm, LutAxes::covering(nodes, (20.0, 60.0), 30.0, (20.0, 15.0, 90.0))).unwrap())
}

/// The scene's atmosphere with the gases on, the same with another aerosol, and the first
/// without gases.
fn atmospheres(scene: &Scene) -> [AtmosphereSpec; 3] {
    let mut a = scene.spec.atmosphere.clone();
    a.day_of_year = scene.day_of_year;
    a.gases = true;
    let other = AtmosphereSpec { aerosol: AerosolType::Maritime, aot550: 0.3, ..a.clone() };
    let gas_free = AtmosphereSpec { gases: false, ..a.clone() };
    [a, other, gas_free]
}

#[test]
fn shared_gas_factors_give_each_atmosphere_its_own_spectrum_bit_for_bit() {
    let mut spec = small_lake();
    (spec.width, spec.height) = (40, 40);
    let scene = Scene::build(&spec, None).unwrap();
    let grid = WavelengthGrid::uniform(400.0, 900.0, 1.0).unwrap();
    let [a, b, free] = atmospheres(&scene).map(|s| PathOptics::new(&scene, &grid, lut(&s)).unwrap());
    let g = Geometry::from_degrees(40.0, 12.0, 75.0);
    let legs = a.gas_legs(&g).unwrap();
    assert_eq!(a.gas_key(), b.gas_key());
    assert_eq!(b.path_spectrum_with(&g, &legs).unwrap(), b.path_spectrum(&g).unwrap());
    assert_eq!(a.path_spectrum_with(&g, &legs).unwrap(), a.path_spectrum(&g).unwrap());
    // Legs that do not fit are not used: another atmosphere's gases, another geometry, another grid.
    assert_ne!(free.gas_key(), a.gas_key());
    let own = free.path_spectrum(&g).unwrap();
    assert_eq!(free.path_spectrum_with(&g, &legs).unwrap(), own);
    assert!(own.t_up.iter().zip(&b.path_spectrum(&g).unwrap().t_up).any(|(x, y)| x > y), "gases absorb somewhere");
    let other_view = Geometry::from_degrees(40.0, 25.0, 75.0);
    assert_eq!(b.path_spectrum_with(&other_view, &legs).unwrap(), b.path_spectrum(&other_view).unwrap());
    let coarse =
        PathOptics::new(&scene, &WavelengthGrid::uniform(400.0, 900.0, 2.0).unwrap(), lut(&atmospheres(&scene)[0]))
            .unwrap();
    assert_eq!(coarse.path_spectrum_with(&g, &legs).unwrap(), coarse.path_spectrum(&g).unwrap());
    // The band terms' entries alone, at the indices a band weighs, are the full spectrum's.
    let needed: Vec<bool> = (0..grid.len()).map(|i| (100..160).contains(&i) || i % 7 == 0).collect();
    let (part, full) = (b.band_path_with(&g, &legs, &needed).unwrap(), b.path_spectrum(&g).unwrap());
    for i in 0..grid.len() {
        let pairs = [
            (part.l_path[i], full.l_path[i]),
            (part.ed[i], full.ed[i]),
            (part.t_up[i], full.t_up[i]),
            (part.spherical_albedo[i], full.spherical_albedo[i]),
            (part.glint[i], full.glint[i]),
        ];
        for (k, (x, y)) in pairs.into_iter().enumerate() {
            assert_eq!(x, if needed[i] { y } else { 0.0 }, "term {k} at index {i}");
        }
        assert!(full.ed[i] > 0.0);
    }
    assert!(part.ed_direct.is_empty() && part.t_up_diffuse.is_empty() && part.rayleigh_share.is_empty());
    // The scene's optics read the same path.
    let optics = SceneOptics::new(&scene, &grid, lut(&atmospheres(&scene)[0])).unwrap();
    assert_eq!(optics.path_spectrum(&g).unwrap(), a.path_spectrum(&g).unwrap());
}

#[test]
fn gas_legs_are_the_one_wavelength_gas_factors_bit_for_bit() {
    // Through the WASI band models (ozone, O₂ A band, water vapour at 940 nm) and the SWIR table.
    let atm = AtmosphereSpec { gases: true, ..AtmosphereSpec::default() }.build().unwrap();
    let wavelengths = [350.0, 443.0, 600.0, 761.0, 940.0, 1000.0, 1375.0, 1640.0, 2200.0];
    for (mu0, muv) in [(0.9, 1.0), (0.5, 0.8), (0.2, 0.35)] {
        let legs = atm.gas_legs(&wavelengths, mu0, muv).unwrap();
        for (i, &w) in wavelengths.iter().enumerate() {
            assert_eq!(legs.down[i], atm.gas(w, mu0).unwrap(), "T(m0) at {w} nm");
            assert_eq!(legs.up_after_down[i], atm.gas_up_after_down(w, mu0, muv).unwrap(), "up factor at {w} nm");
        }
        assert!(legs.down[3] < 0.9 && legs.down[1] > 0.99, "{:?}", legs.down);
    }
}

#[test]
fn band_terms_of_several_atmospheres_are_each_ones_own_bit_for_bit() {
    let mut spec = small_lake();
    (spec.width, spec.height) = (200, 200);
    let scene = Scene::build(&spec, None).unwrap();
    let mut inst = InstrumentSpec::preset("cubesat").unwrap();
    inst.detectors = 90;
    let response = Response::new(&inst, 1.0).unwrap();
    let sun = (scene.spec.sun.zenith_deg.to_radians(), scene.spec.sun.azimuth_deg.to_radians());
    let viewing = Viewing::new(&inst, &response, sun.0, sun.1, 1, None).unwrap();
    let bound: Vec<Vec<SceneOptics>> = atmospheres(&scene)
        .iter()
        .map(|s| {
            let l = lut(s);
            response.groups.iter().map(|g| SceneOptics::new(&scene, &g.grid, l.clone()).unwrap()).collect()
        })
        .collect();
    // Across track (33 sampled columns interpolated) and at every column.
    for across_track in [Some(shoal::instrument::band_atmosphere::TERM_COLUMNS), None] {
        let paths: Vec<Vec<&PathOptics>> = bound.iter().map(|o| o.iter().map(SceneOptics::path).collect()).collect();
        let together = band_terms_of_each(&paths, &viewing, &response, across_track).unwrap();
        for (o, t) in bound.iter().zip(&together) {
            let alone = band_terms(o, &viewing, &response, across_track).unwrap();
            assert_eq!(alone.l_path, t.l_path);
            assert_eq!(alone.t_ed, t.t_ed);
            assert_eq!(alone.spherical_albedo, t.spherical_albedo);
            assert_eq!(alone.glint, t.glint);
        }
    }
}

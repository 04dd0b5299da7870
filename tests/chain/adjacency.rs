//! The adjacency effect does not depend on the scene's extent: the same 300 m island in a 4 km
//! and in a 20 km scene of the same water sends the same adjacency radiance into the pixels next
//! to it. (Renormalising the environment kernel to the scene's window made the small scene's
//! adjacency 1.34× larger at 443 nm and 1.18× at 865 nm.)

use crate::common::Kept;
use shoal::engine::RunConfig;
use shoal::instrument::InstrumentSpec;
use shoal::scene::{Effect, MapSpec, SceneSpec};

use super::run;

/// Constant water (chl 5, NAP 2, CDOM 0.5, deep) with an island of radius 150 m at the centre,
/// `size_m` on a side in 20 m cells.
fn island_scene(size_m: f64, adjacency: bool) -> SceneSpec {
    let mut s = SceneSpec::preset("lake_hume_bloom").unwrap();
    let cells = (size_m / 20.0) as usize;
    (s.width, s.height, s.cell_m) = (cells, cells, 20.0);
    s.chl_mg_m3 = MapSpec::Constant(5.0);
    s.nap_g_m3 = MapSpec::Constant(2.0);
    s.cdom_per_m = MapSpec::Constant(0.5);
    s.depth_m = None;
    s.substrates.clear();
    s.land = Some(
        ron::from_str(
            "(mask: Shapes(background: 0.0, shapes: [Ellipse(centre_m: (0.0, 0.0), radii_m: (150.0, 150.0), \
             angle_deg: 0.0, value: 1.0)]), reflectance: Table(wavelength_nm: [350.0, 500.0, 680.0, 720.0, \
             800.0, 1000.0], values: [0.03, 0.05, 0.04, 0.25, 0.42, 0.42]))",
        )
        .unwrap(),
    );
    s.effects = if adjacency { vec![Effect::Adjacency] } else { Vec::new() };
    s
}

/// Adjacency radiance (with minus without) at 443 and 865 nm in the pixel 100–120 m east of the
/// island's shore, W m⁻² sr⁻¹ nm⁻¹.
fn adjacency_radiance(size_m: f64) -> (f64, f64) {
    let mut instrument = InstrumentSpec::preset("cubesat").unwrap();
    (instrument.detectors, instrument.lines) = (40, 3);
    let radiance = |adjacency: bool| {
        let mut c = RunConfig::new(island_scene(size_m, adjacency), instrument.clone());
        c.detector.noise = false;
        run(&c).kept().radiance.radiance.clone()
    };
    let (with, without) = (radiance(true), radiance(false));
    // Detector 33 of 40 looks ~13 GSD (≈ 260 m) east of the centre line; line 1 is the middle one.
    let (r, c) = (1, 33);
    let band = |b: usize| f64::from(with[[r, c, b]] - without[[r, c, b]]);
    (band(2), band(16)) // Oa03 442.5 nm, Oa17 865 nm
}

#[test]
fn an_island_sends_the_same_adjacency_radiance_in_a_4_km_and_a_20_km_scene() {
    let (small_443, small_865) = adjacency_radiance(4000.0);
    let (large_443, large_865) = adjacency_radiance(20_000.0);
    eprintln!(
        "adjacency radiance next to the island: 443 nm {small_443:.4e} (4 km) vs {large_443:.4e} (20 km), ratio \
         {:.4}; 865 nm {small_865:.4e} vs {large_865:.4e}, ratio {:.4}",
        small_443 / large_443,
        small_865 / large_865
    );
    // It is there (the island is bright in the NIR, darker than water in the blue)…
    assert!(small_865 > 0.0 && large_865 > 0.0);
    assert!(small_443.abs() > 0.0);
    // …and the same in both scenes: 3 % (the bound; the kernels at every offset the
    // island reaches are identical, so only f32 FFT rounding differs).
    assert!((small_443 / large_443 - 1.0).abs() < 0.03, "443 nm: {small_443} vs {large_443}");
    assert!((small_865 / large_865 - 1.0).abs() < 0.03, "865 nm: {small_865} vs {large_865}");
}

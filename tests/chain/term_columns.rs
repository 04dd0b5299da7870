//! The band terms at a few columns interpolated across the swath, against every column's: how
//! far the family's [`TERM_COLUMNS`] (and a preview's [`term_columns`]) leave the terms.

use std::sync::Arc;

use shoal::atmosphere::AtmosphereLut;
use shoal::engine::{Fidelity, lut_axes_covering};
use shoal::instrument::band_atmosphere::{TERM_COLUMNS, band_terms, term_columns};
use shoal::instrument::{InstrumentSpec, Response, Viewing};
use shoal::scene::{Scene, SceneSpec};
use shoal::toa::SceneOptics;

/// Largest relative difference of path radiance, T·Ed and S between the terms at
/// [`term_columns`] and at every column of `inst`, under the Lake Hume scene's atmosphere and
/// sun, at each of `decimations`.
fn worst(inst: &InstrumentSpec, decimations: &[usize]) -> Vec<[f64; 3]> {
    let mut spec = SceneSpec::preset("lake_hume_bloom").unwrap();
    // The water is not read: a small scene keeps the test short.
    (spec.width, spec.height) = (64, 64);
    let scene = Scene::build(&spec, None).unwrap();
    let response = Response::new(inst, 1.0).unwrap();
    let sun = (spec.sun.zenith_deg.to_radians(), spec.sun.azimuth_deg.to_radians());
    let viewing = |d: usize| Viewing::new(inst, &response, sun.0, sun.1, d, None).unwrap();
    let sza = (spec.sun.zenith_deg, spec.sun.zenith_deg);
    let axes = lut_axes_covering(&response, sza, viewing(1).max_view_zenith_deg, &Fidelity::default());
    let mut atmosphere = spec.atmosphere.clone();
    atmosphere.day_of_year = scene.day_of_year;
    let lut = Arc::new(AtmosphereLut::build(&atmosphere.build().unwrap(), axes).unwrap());
    let optics: Vec<SceneOptics> =
        response.groups.iter().map(|g| SceneOptics::new(&scene, &g.grid, lut.clone()).unwrap()).collect();
    let rel = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| ((x - y) / y).abs()).fold(0.0, f64::max);
    decimations
        .iter()
        .map(|&d| {
            let v = viewing(d);
            let every = band_terms(&optics, &v, &response, None).unwrap();
            let few = band_terms(&optics, &v, &response, Some(term_columns(d))).unwrap();
            [
                rel(&few.l_path, &every.l_path),
                rel(&few.t_ed, &every.t_ed),
                rel(&few.spherical_albedo, &every.spherical_albedo),
            ]
        })
        .collect()
}

/// Tolerances: an error δ in the path radiance moves Rrs by about δ·L_path/L_w, ten times δ in
/// the blue over dark water. At full resolution 10⁻⁴ keeps that to 0.1 % (far below any design's
/// noise); a preview's 10⁻³ to 1 %, below what a 1/24 preview's pixel sample moves the metrics.
#[test]
fn few_columns_interpolated_stay_near_every_column() {
    // The CubeSat's 10 km half swath and OLCI's 111 km (7.8°), each across nadir.
    for (name, full_bound) in [("cubesat", 1e-5), ("sentinel3a_olci", 1e-4)] {
        let inst = InstrumentSpec::preset(name).unwrap();
        let decimations = [1, 2, 4, 24];
        for (d, w) in decimations.iter().zip(worst(&inst, &decimations)) {
            let k = term_columns(*d);
            eprintln!("{name} 1/{d}, {k} columns: L_path {:.2e}, T·Ed {:.2e}, S {:.2e}", w[0], w[1], w[2]);
            let bound = if *d == 1 { full_bound } else { 1e-3 };
            assert!(w.iter().all(|e| *e < bound), "{name} at 1/{d}: {w:?} against {bound}");
            // The columns were interpolated (an image narrower than k columns would compute them all).
            assert!(w[0] > 0.0, "{name} at 1/{d}: no column was interpolated");
        }
    }
    assert_eq!(term_columns(1), TERM_COLUMNS);
}

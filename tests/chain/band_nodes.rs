//! Per-pixel spectra at band nodes (`Fidelity::band_nodes`): the approximation against the full
//! grid, noise-free, on a deep lake, a shallow reef (bottom and substrate mixture) and a
//! hyperspectral instrument (many narrow bands), and the land and adjacency fallbacks.

use crate::common::Kept;
use shoal::engine::RunConfig;
use shoal::instrument::DetectorMode;

use shoal::scene::{Effect, SceneSpec};

use super::{reef, run, small, small_lake};

/// A scene without adjacency (which keeps the full grid).
fn without_adjacency(mut scene: SceneSpec) -> SceneSpec {
    scene.effects.retain(|e| *e != Effect::Adjacency);
    scene
}

/// Largest |a/b − 1| over elements with |b| above `floor`.
fn worst(a: &ndarray::Array3<f32>, b: &ndarray::Array3<f32>, floor: f32) -> f64 {
    a.iter()
        .zip(b)
        .filter(|(_, y)| y.abs() > floor)
        .map(|(x, y)| (f64::from(*x) / f64::from(*y) - 1.0).abs())
        .fold(0.0, f64::max)
}

fn config(scene: SceneSpec, instrument: &str, nodes: usize) -> RunConfig {
    let mut c = RunConfig::new(scene, small(instrument, 96, 64));
    c.detector = DetectorMode::IDEAL;
    c.fidelity.band_nodes = nodes;
    // One approximation at a time: the kernel's precision is the last test's subject.
    c.fidelity.water_single_precision = false;
    c
}

#[test]
fn band_nodes_reproduce_the_grid_radiance_and_truth() {
    // Tolerances: twice the worst case measured over these scenes (4 nodes: radiance 7.6e-4,
    // truth 2.6e-3, both on the reef; 2 nodes: 3.2e-3 and 9.0e-3 on the lake). The error is the
    // within-band curvature of Rrs, largest at 700–760 nm where pure-water absorption rises
    // steeply; its effect on the products is the cost table's chl error.
    for (scene, instrument, nodes, radiance_tol, truth_tol) in [
        (small_lake(), "nominal", 4, 1.5e-3, 5.2e-3),
        (without_adjacency(reef()), "cubesat", 4, 1.5e-3, 5.2e-3),
        (small_lake(), "hyperspectral", 4, 1.5e-3, 5.2e-3),
        (small_lake(), "nominal", 2, 6.4e-3, 1.8e-2),
    ] {
        let grid = run(&config(scene.clone(), instrument, 0));
        let nodes_run = run(&config(scene.clone(), instrument, nodes));
        let radiance = worst(&nodes_run.kept().radiance.radiance, &grid.kept().radiance.radiance, 0.0);
        let truth = worst(&nodes_run.kept().radiance.truth_rrs, &grid.kept().radiance.truth_rrs, 1e-4);
        println!("{} / {instrument}, {nodes} nodes: radiance {radiance:.2e}, truth Rrs {truth:.2e}", scene.name);
        assert!(radiance > 0.0, "{instrument}: the node path did not run");
        assert!(radiance < radiance_tol, "{} / {instrument}: radiance off by {radiance:.2e}", scene.name);
        assert!(truth < truth_tol, "{} / {instrument}: truth Rrs off by {truth:.2e}", scene.name);
        // The same pixels evaluated: nothing skipped, nothing added.
        assert_eq!(nodes_run.report.water_evaluations, grid.report.water_evaluations);
    }
}

#[test]
fn land_and_adjacency_keep_the_full_grid() {
    // Adjacency needs whole spectra: a scene that asks for it ignores band nodes, bit for bit.
    let scene = reef();
    assert!(scene.effects.contains(&Effect::Adjacency));
    let grid = run(&config(scene.clone(), "cubesat", 0));
    let nodes = run(&config(scene, "cubesat", 4));
    assert_eq!(nodes.kept().radiance.radiance, grid.kept().radiance.radiance);
    // Land pixels take the grid path: their radiance is the grid's, bit for bit.
    // The whole swath at 1/8 resolution, so the shore is in view.
    let scene = without_adjacency(SceneSpec::preset("reservoir_chl_cdom").unwrap());
    let whole = |nodes: usize| {
        let mut c = RunConfig::new(scene.clone(), shoal::instrument::InstrumentSpec::preset("nominal").unwrap());
        c.detector = DetectorMode::IDEAL;
        c.fidelity.decimation = 8;
        c.fidelity.band_nodes = nodes;
        c
    };
    let grid = run(&whole(0));
    let nodes = run(&whole(4));
    let land = &grid.truth.surface.codes();
    let n_land = land.iter().filter(|&&l| l != 0).count();
    assert!(n_land > 0 && n_land < land.len(), "the scene has land and water in view ({n_land} land)");
    for ((r, c), &l) in land.indexed_iter() {
        if l != 0 {
            for b in 0..grid.kept().radiance.radiance.dim().2 {
                assert_eq!(
                    nodes.kept().radiance.radiance[[r, c, b]],
                    grid.kept().radiance.radiance[[r, c, b]],
                    "land ({r}, {c})"
                );
            }
        }
    }
    assert!(nodes.kept().radiance.radiance != grid.kept().radiance.radiance, "the water took the node path");
}

#[test]
fn the_single_precision_water_kernel_gives_the_same_products_within_its_rounding() {
    // Rrs from the f32 kernel is within 2e-6 of the f64 one (`water::single` tests); through the
    // band integrals and the f32 cubes the radiance and truth may differ by a few f32 ulps more.
    // Tolerance 1e-5: five times the kernel's bound, a hundred times below the band nodes' own
    // error above.
    for (scene, instrument) in [(small_lake(), "nominal"), (without_adjacency(reef()), "cubesat")] {
        let double = run(&config(scene.clone(), instrument, 4));
        let mut c = config(scene.clone(), instrument, 4);
        c.fidelity.water_single_precision = true;
        let single = run(&c);
        let radiance = worst(&single.kept().radiance.radiance, &double.kept().radiance.radiance, 0.0);
        let truth = worst(&single.kept().radiance.truth_rrs, &double.kept().radiance.truth_rrs, 1e-4);
        println!("{} / {instrument}: radiance {radiance:.2e}, truth Rrs {truth:.2e}", scene.name);
        assert!(radiance > 0.0, "{instrument}: the single-precision kernel did not run");
        assert!(radiance < 1e-5 && truth < 1e-5, "{}: radiance {radiance:.2e}, truth {truth:.2e}", scene.name);
    }
}

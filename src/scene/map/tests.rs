//! Maps: gradients, random fields, shapes and images against hand-computed values.

use super::*;

fn extent() -> Extent {
    Extent { width: 100, height: 50, cell_m: 10.0 }
}

#[test]
fn gradient_spans_the_scene() {
    let m = Map::build(
        &MapSpec::Gradient { from: 1.0, to: 7.0, angle_deg: 0.0 },
        extent(),
        "depth",
        &mut MapContext::default(),
    )
    .unwrap();
    assert!((m.value_at(-500.0, 0.0) - 1.0).abs() < 1e-12);
    assert!((m.value_at(500.0, 0.0) - 7.0).abs() < 1e-12);
    assert!((m.value_at(0.0, 200.0) - 4.0).abs() < 1e-12);
}

#[test]
fn random_field_is_log_normal_and_clamped() {
    let spec = MapSpec::RandomField {
        distribution: Distribution::LogNormal { median: 10.0, sigma_ln: 1.0 },
        correlation_m: 50.0,
        seed: 1,
        clamp: Some((1.0, 100.0)),
    };
    let m = Map::build(&spec, extent(), "chl", &mut MapContext::default()).unwrap();
    let (lo, hi) = m.range();
    assert!(lo >= 1.0 && hi <= 100.0 && lo < 3.0 && hi > 30.0, "{lo} {hi}");
}

#[test]
fn shapes_make_bathymetry() {
    let spec = MapSpec::Shapes {
        background: 7.0,
        shapes: vec![
            Shape::Ellipse { centre_m: (0.0, 0.0), radii_m: (200.0, 100.0), angle_deg: 0.0, value: 2.0, edge_m: 0.0 },
            Shape::Ridge { from_m: (-400.0, -200.0), to_m: (400.0, -200.0), width_m: 20.0, amplitude: -3.0 },
        ],
    };
    let m = Map::build(&spec, extent(), "depth", &mut MapContext::default()).unwrap();
    assert_eq!(m.value_at(0.0, 0.0), 2.0);
    assert_eq!(m.value_at(300.0, 150.0), 7.0);
    assert!((m.value_at(0.0, -200.0) - 4.0).abs() < 1e-9);
}

#[test]
fn missing_image_names_the_field_and_file() {
    let spec = MapSpec::Image { path: "no/such.png".into(), min: 0.0, max: 10.0 };
    let e = Map::build(&spec, extent(), "maps.depth_m", &mut MapContext::default()).unwrap_err().to_string();
    assert!(e.contains("maps.depth_m") && e.contains("no/such.png"), "{e}");
}

#[test]
fn images_stretch_over_the_scene() {
    let dir = std::env::temp_dir().join(format!("shoal-map-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Two columns: black (west) and white (east).
    let img = image::GrayImage::from_fn(2, 2, |x, _| image::Luma([if x == 0 { 0 } else { 255 }]));
    img.save(dir.join("two.png")).unwrap();
    let spec = MapSpec::Image { path: "two.png".into(), min: 1.0, max: 9.0 };
    let m = Map::build(&spec, extent(), "depth", &mut MapContext { base_dir: Some(&dir), ..MapContext::default() })
        .unwrap();
    assert!((m.value_at(-490.0, 0.0) - 1.0).abs() < 1e-9);
    assert!((m.value_at(490.0, 0.0) - 9.0).abs() < 1e-9);
    std::fs::remove_dir_all(&dir).unwrap();
}

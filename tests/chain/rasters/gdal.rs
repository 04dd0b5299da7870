//! GDAL against Shoal: what GDAL writes, Shoal reads with the same numbers; what Shoal writes,
//! `gdalinfo` reads with its CRS, geotransform, nodata and values (Debian's gdal-bin).

use super::*;

#[test]
fn the_reader_reads_what_gdal_writes() {
    if !crate::common::tool_available("gdalinfo", "gdal-bin") {
        return;
    }
    // GDAL writes the layouts survey data come in; our reader must give the same numbers.
    let dir = tempdir("gdal-variants");
    let habitat = rasters_dir().join("reef_survey_habitat.tif");
    let ours = read(&habitat).unwrap();
    let variants: [(&str, &[&str], f64, f64, f64); 4] = [
        // (name, gdal_translate options, scale, offset, tolerance): file value = (v − offset)/scale.
        (
            "f64_tiled_lzw_pixel",
            &[
                "-ot",
                "Float64",
                "-co",
                "TILED=YES",
                "-co",
                "BLOCKXSIZE=64",
                "-co",
                "BLOCKYSIZE=32",
                "-co",
                "COMPRESS=LZW",
                "-co",
                "INTERLEAVE=PIXEL",
            ],
            1.0,
            0.0,
            0.0,
        ),
        (
            "f32_strips_deflate_band",
            &["-ot", "Float32", "-co", "COMPRESS=DEFLATE", "-co", "INTERLEAVE=BAND", "-co", "PREDICTOR=3"],
            1.0,
            0.0,
            0.0,
        ),
        // Integers: GDAL rounds (v·1000) to the nearest count; we undo the scaling.
        (
            "u16_lzw",
            &["-ot", "UInt16", "-scale", "0", "1", "0", "1000", "-co", "COMPRESS=LZW", "-co", "PREDICTOR=2"],
            1000.0,
            0.0,
            0.5e-3,
        ),
        ("i16_tiled", &["-ot", "Int16", "-scale", "0", "1", "-500", "500", "-co", "TILED=YES"], 1000.0, -500.0, 0.5e-3),
    ];
    for (name, options, scale, offset, tolerance) in variants {
        let out = dir.join(format!("{name}.tif"));
        run_gdal(
            "gdal_translate",
            ["-q"]
                .iter()
                .chain(options)
                .map(|s| s.to_string())
                .chain([habitat.display().to_string(), out.display().to_string()]),
        );
        let theirs = read(&out).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((theirs.width, theirs.height, theirs.bands.len()), (152, 102, 4), "{name}");
        assert_eq!(theirs.geotransform, ours.geotransform, "{name}");
        assert_eq!(theirs.crs, ours.crs, "{name}");
        for b in 0..4 {
            let worst = ours.bands[b]
                .iter()
                .zip(&theirs.bands[b])
                .map(|(v, t)| (v - (t - offset) / scale).abs())
                .fold(0.0f64, f64::max);
            // +1e-7: the integer variants round 0.5-count ties either way.
            assert!(worst <= tolerance + 1e-7, "{name} band {}: worst difference {worst}", b + 1);
        }
    }
    // And a scene can use the integer file with its scale: the sand map agrees to a count.
    let u16_file = dir.join("u16_lzw.tif");
    let scene = build_edited(
        "u16",
        |t| {
            t.replace(
                r#"Raster(path: "rasters/reef_survey_habitat.tif", band: 2, unit: "1")"#,
                &format!(r#"Raster(path: "{}", band: 2, scale: 0.001, unit: "1")"#, u16_file.display()),
            )
        },
        |_| {},
    )
    .unwrap();
    let reference = survey_scene();
    let sand = |s: &Scene| s.substrates.iter().find(|(n, _)| n == "sand").unwrap().1.clone();
    let (a, b) = (sand(&scene), sand(&reference));
    for (col, row) in [(150, 100), (40, 30), (250, 170)] {
        let (x, y) = scene_xy(col, row);
        assert!((a.value_at(x, y) - b.value_at(x, y)).abs() <= 0.5e-3 + 1e-7);
    }
    // The same counts with GDAL's own band scale (`-a_scale`): the file unpacks itself, so the
    // scene states no scale and gets fractions, not counts 1000 times too large.
    let packed = dir.join("u16_packed.tif");
    run_gdal(
        "gdal_translate",
        ["-q", "-a_scale", "0.001", "-a_offset", "0", u16_file.to_str().unwrap(), packed.to_str().unwrap()]
            .map(String::from),
    );
    assert_eq!(read(&packed).unwrap().scales[1], (0.001, 0.0));
    let scene = build_edited(
        "u16-packed",
        |t| {
            t.replace(
                r#"Raster(path: "rasters/reef_survey_habitat.tif", band: 2, unit: "1")"#,
                &format!(r#"Raster(path: "{}", band: 2, unit: "1")"#, packed.display()),
            )
        },
        |_| {},
    )
    .unwrap();
    let a = sand(&scene);
    for (col, row) in [(150, 100), (40, 30), (250, 170)] {
        let (x, y) = scene_xy(col, row);
        assert!((a.value_at(x, y) - b.value_at(x, y)).abs() <= 0.5e-3 + 1e-7, "{}", a.value_at(x, y));
    }
}

/// `gdalinfo -json -stats` of `path`, parsed.
fn gdalinfo(path: &Path) -> serde_json::Value {
    let text = run_gdal("gdalinfo", ["-json".to_string(), "-stats".into(), path.display().to_string()]);
    let _ = std::fs::remove_file(path.with_extension("tif.aux.xml"));
    serde_json::from_str(&text).unwrap()
}

/// A band statistic of `gdalinfo -json -stats` at full precision (the top-level `mean` is
/// rounded to three decimals).
fn gdal_stat(band: &serde_json::Value, name: &str) -> f64 {
    band["metadata"][""][format!("STATISTICS_{name}")].as_str().unwrap().parse().unwrap()
}

/// Mean, min and max of the finite values of `values` where `keep`.
fn stats(values: impl Iterator<Item = (f64, bool)>) -> (f64, f64, f64) {
    let (mut n, mut sum, mut lo, mut hi) = (0usize, 0.0, f64::INFINITY, f64::NEG_INFINITY);
    for (v, keep) in values {
        if keep && v.is_finite() {
            (n, sum, lo, hi) = (n + 1, sum + v, lo.min(v), hi.max(v));
        }
    }
    (sum / n as f64, lo, hi)
}

#[test]
fn gdal_reads_the_products_we_write_with_their_crs_transform_nodata_and_values() {
    if !crate::common::tool_available("gdalinfo", "gdal-bin") {
        return;
    }
    use shoal::engine::RunConfig;
    use shoal::retrieval::RetrievalSpec;
    let scene = SceneSpec::preset("reef_survey_raster").unwrap();
    let mut config = RunConfig::new(scene, shoal::instrument::InstrumentSpec::preset("nominal").unwrap());
    config.retrievals = vec![RetrievalSpec::Sambuca { siop: None, substrates: None, settings: Default::default() }];
    config.fidelity.decimation = 2;
    let out = crate::run(&config);
    let dir = tempdir("products");
    let written = shoal::study::write_run_geotiff(&out, &dir).unwrap();
    assert!(written.files.iter().any(|f| f == "sambuca.tif"), "{:?}", written.files);
    let truth = &out.truth;
    let (g, residual_m) = shoal::study::swath_geotransform(&out.viewing, (ORIGIN.0 + 1200.0, ORIGIN.1 - 800.0));
    assert!(residual_m < 0.01, "a nadir 2 km swath is affine to well under a centimetre: {residual_m} m");

    let info = gdalinfo(&dir.join("truth.tif"));
    let wkt = info["coordinateSystem"]["wkt"].as_str().unwrap();
    assert!(wkt.contains(r#"ID["EPSG",32756]"#), "{wkt}");
    let gt: Vec<f64> = info["geoTransform"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    for k in 0..6 {
        assert!((gt[k] - g[k]).abs() <= 1e-6 * g[k].abs().max(1.0), "geotransform {gt:?} vs {g:?}");
    }
    // The image's centre is the scene's centre (the track runs through it), to a pixel.
    let (rows, cols) = (out.viewing.lines() as f64, out.viewing.columns() as f64);
    let centre = (g[0] + g[1] * cols / 2.0 + g[2] * rows / 2.0, g[3] + g[4] * cols / 2.0 + g[5] * rows / 2.0);
    assert!(
        (centre.0 - 385_200.0).abs() < 2.0 * out.viewing.gsd_m
            && (centre.1 - 7_405_200.0).abs() < 2.0 * out.viewing.gsd_m
    );
    let bands = info["bands"].as_array().unwrap();
    // chl, NAP, CDOM, depth, three substrate fractions, land.
    assert_eq!(bands.len(), 8);
    assert_eq!(bands[3]["description"], "true depth");
    assert_eq!(bands[3]["unit"], "m");
    assert_eq!(bands[3]["noDataValue"], -9999.0);
    let water = |(r, c): (usize, usize)| truth.surface.codes()[[r, c]] == 0;
    let depth = truth.depth_m.as_ref().unwrap();
    let (mean, lo, hi) = stats(depth.indexed_iter().map(|(i, v)| (f64::from(*v), water(i))));
    let s = &bands[3];
    // GDAL sums in double the Float32 values we wrote, as we do here: agreement to rounding.
    assert!((gdal_stat(s, "MEAN") - mean).abs() < 1e-9 * mean, "{s} vs {mean}");
    assert!((gdal_stat(s, "MINIMUM") - lo).abs() < 1e-9 && (gdal_stat(s, "MAXIMUM") - hi).abs() < 1e-9);
    let land_pixels = truth.surface.codes().iter().filter(|v| **v != 0).count();
    assert!(land_pixels > 0, "the cay is in the image");
    assert_eq!(bands[7]["description"], "surface class: 0 water, 1 land, 2 cloud, 3 cloud_shadow");
    let land_mean = land_pixels as f64 / truth.surface.codes().len() as f64;
    assert!((gdal_stat(&bands[7], "MEAN") - land_mean).abs() < 1e-9);

    let info = gdalinfo(&dir.join("sambuca.tif"));
    let bands = info["bands"].as_array().unwrap();
    assert_eq!(bands[3]["description"], "retrieved depth");
    let p = &out.retrievals[0].product;
    let returned = |(r, c): (usize, usize)| p.returned(r, c);
    let (mean, _, _) = stats(p.depth_m.as_ref().unwrap().indexed_iter().map(|(i, v)| (f64::from(*v), returned(i))));
    assert!((gdal_stat(&bands[3], "MEAN") - mean).abs() < 1e-9 * mean);
    // Not-returned pixels (land) are nodata, so GDAL's valid share is the returned share.
    let returned_pct = 100.0
        * p.flags.iter().filter(|f| **f & shoal::retrieval::ProductFlags::RETURNED != 0).count() as f64
        / p.flags.len() as f64;
    let valid_pct = gdal_stat(&bands[3], "VALID_PERCENT");
    assert!((valid_pct - returned_pct).abs() < 0.01, "{valid_pct} vs {returned_pct}");

    let info = gdalinfo(&dir.join("rrs.tif"));
    assert_eq!(info["bands"].as_array().unwrap().len(), out.response.bands.bands.len());
    assert_eq!(info["bands"][0]["unit"], "sr-1");
}

#[test]
fn a_scene_without_a_georeference_is_written_in_a_local_metric_frame() {
    if !crate::common::tool_available("gdalinfo", "gdal-bin") {
        return;
    }
    let mut config = shoal::engine::RunConfig::new(
        crate::small_lake(),
        shoal::instrument::InstrumentSpec::preset("nominal").unwrap(),
    );
    config.fidelity.decimation = 16;
    let out = crate::run(&config);
    let dir = tempdir("local");
    shoal::study::write_run_geotiff(&out, &dir).unwrap();
    let info = gdalinfo(&dir.join("truth.tif"));
    let wkt = info["coordinateSystem"]["wkt"].as_str().unwrap();
    assert!(wkt.starts_with("ENGCRS[\"Shoal scene frame") && wkt.contains("metre"), "{wkt}");
    let back = read(&dir.join("truth.tif")).unwrap();
    assert!(matches!(back.crs, Crs::LocalMetres { .. }));
    assert_eq!(back.bands[0].len(), out.viewing.lines() * out.viewing.columns());
}

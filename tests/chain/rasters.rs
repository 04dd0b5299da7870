//! Scenes from GeoTIFF rasters: the example reef survey the project ships (and the script that
//! makes it), resampling through both geotransforms, nodata and unit checks, and what breaks a
//! raster scene with a clear error.
//!
//! The rasters in `presets/scenes/rasters/` are made by [`reef_survey`] and nothing else:
//! `cargo test --test chain -- --ignored regenerate_the_example_rasters` rewrites them, and
//! `the_shipped_rasters_are_what_the_script_makes` fails when they drift apart.

use std::path::{Path, PathBuf};

use shoal::geotiff::{Crs, Raster, encode, read};
use shoal::scene::{Scene, SceneSpec};

/// Top-left corner of the bathymetry grid, WGS 84 / UTM zone 56S (EPSG:32756), m: a patch reef
/// of the Capricorn Group near Heron Island (23.44 S, 151.91 E lies at about 385 km E,
/// 7 407 km N).
const ORIGIN: (f64, f64) = (384_000.0, 7_406_000.0);
const UTM_56S: u16 = 32756;
/// Bathymetry grid: 300 × 200 cells of 8 m (2.4 × 1.6 km).
const BATHY: (usize, usize, f64) = (300, 200, 8.0);
/// Habitat grid: 16 m cells, one cell wider on every side than the bathymetry, so the scene's
/// cells fall between the habitat map's and are resampled.
const HABITAT: (usize, usize, f64) = (152, 102, 16.0);
const NODATA: f64 = -9999.0;

fn logistic(d: f64, edge_m: f64) -> f64 {
    1.0 / (1.0 + (d / edge_m).exp())
}

/// Signed distance-like coordinate of (x, y) to an ellipse (negative inside), m.
fn ellipse(x: f64, y: f64, centre: (f64, f64), radii: (f64, f64), angle_deg: f64) -> f64 {
    let (s, c) = angle_deg.to_radians().sin_cos();
    let (dx, dy) = (x - centre.0, y - centre.1);
    let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
    let scale = radii.0.min(radii.1);
    ((u / radii.0).hypot(v / radii.1) - 1.0) * scale
}

/// The cay (vegetated sand island) at the reef's western end, on the habitat grid: 1 inside.
fn cay(x: f64, y: f64) -> bool {
    ellipse(x, y, (760.0, -820.0), (210.0, 110.0), 12.0) < 0.0
}

/// Depth of the reef at (x, y) m east and south of the bathymetry's top-left corner (y < 0):
/// a 9.5 m sandy surround, a reef flat at 1.4–2.2 m (an oval 1.7 × 0.8 km), a lagoon to 4 m,
/// and a groove cut through the southern rim.
fn depth_m(x: f64, y: f64) -> f64 {
    let platform = logistic(ellipse(x, y, (1250.0, -800.0), (850.0, 400.0), 8.0), 25.0);
    let lagoon = logistic(ellipse(x, y, (1380.0, -760.0), (330.0, 170.0), 8.0), 30.0);
    let groove = (-((x - 1500.0).powi(2)) / (2.0 * 50.0f64.powi(2))).exp() * logistic(y + 1000.0, 30.0);
    let flat = 1.8 + 0.4 * ((x / 230.0).sin() * (y / 170.0).cos());
    let d = 9.5 + platform * (flat - 9.5) + lagoon * (4.0 - flat) * platform;
    d + groove * platform * 2.5
}

/// Fractions (acropora, sand, turf algae) at (x, y): coral on the rim, turf on the flat, sand in
/// the lagoon and off the reef.
fn habitat(x: f64, y: f64) -> [f64; 3] {
    let outer = logistic(ellipse(x, y, (1250.0, -800.0), (850.0, 400.0), 8.0), 20.0);
    let inner = logistic(ellipse(x, y, (1250.0, -800.0), (700.0, 290.0), 8.0), 20.0);
    let lagoon = logistic(ellipse(x, y, (1380.0, -760.0), (360.0, 200.0), 8.0), 20.0);
    let acropora = (outer - inner).max(0.0);
    let turf = inner * (1.0 - lagoon);
    [acropora, (1.0 - acropora - turf).max(0.0), turf]
}

/// The example survey: (bathymetry, habitat) as the project ships them.
fn reef_survey() -> (Raster, Raster) {
    let (hw, hh, hc) = HABITAT;
    let h_origin = (ORIGIN.0 - hc, ORIGIN.1 + hc);
    let centre = |origin: (f64, f64), cell: f64, col: usize, row: usize| {
        (origin.0 + (col as f64 + 0.5) * cell - ORIGIN.0, origin.1 - (row as f64 + 0.5) * cell - ORIGIN.1)
    };
    let land_cell = |col: usize, row: usize| {
        let (x, y) = centre(h_origin, hc, col, row);
        cay(x, y)
    };
    let mut bands = vec![Vec::new(); 4];
    for row in 0..hh {
        for col in 0..hw {
            let (x, y) = centre(h_origin, hc, col, row);
            let f = habitat(x, y);
            let land = land_cell(col, row);
            for (b, v) in f.iter().enumerate() {
                bands[b].push(if land { 0.0 } else { (v * 1000.0).round() / 1000.0 });
            }
            bands[3].push(if land { 1.0 } else { 0.0 });
        }
    }
    let mut hab = Raster::new(hw, hh, bands);
    hab.geotransform = Some([h_origin.0, hc, 0.0, h_origin.1, 0.0, -hc]);
    hab.crs = Crs::Projected { epsg: UTM_56S };
    hab.descriptions = ["acropora", "sand", "turf_algae", "land"].map(String::from).to_vec();
    hab.units = vec!["1".into(); 4];
    hab.metadata = vec![("SOURCE".into(), "Shoal example reef survey (tests/chain/rasters.rs), synthetic".into())];

    let (bw, bh, bc) = BATHY;
    let mut depth = Vec::with_capacity(bw * bh);
    for row in 0..bh {
        for col in 0..bw {
            let (x, y) = centre(ORIGIN, bc, col, row);
            // No data where the habitat map's nearest cell is the cay (so land and nodata agree).
            let (hcol, hrow) = (((x + hc) / hc) as usize, ((-y + hc) / hc) as usize);
            depth.push(if land_cell(hcol, hrow) { NODATA } else { (depth_m(x, y) * 100.0).round() / 100.0 });
        }
    }
    let mut bathy = Raster::new(bw, bh, vec![depth]);
    bathy.geotransform = Some([ORIGIN.0, bc, 0.0, ORIGIN.1, 0.0, -bc]);
    bathy.crs = Crs::Projected { epsg: UTM_56S };
    bathy.nodata = Some(NODATA);
    bathy.descriptions = vec!["depth below mean sea level".into()];
    bathy.units = vec!["m".into()];
    bathy.metadata = hab.metadata.clone();
    (bathy, hab)
}

fn rasters_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/scenes/rasters")
}

#[test]
#[ignore = "rewrites presets/scenes/rasters; run it after changing the generator"]
fn regenerate_the_example_rasters() {
    let (bathy, hab) = reef_survey();
    std::fs::create_dir_all(rasters_dir()).unwrap();
    std::fs::write(rasters_dir().join("reef_survey_bathymetry.tif"), encode(&bathy).unwrap()).unwrap();
    std::fs::write(rasters_dir().join("reef_survey_habitat.tif"), encode(&hab).unwrap()).unwrap();
}

#[test]
fn the_shipped_rasters_are_what_the_script_makes() {
    let (bathy, hab) = reef_survey();
    for (name, r) in [("reef_survey_bathymetry.tif", bathy), ("reef_survey_habitat.tif", hab)] {
        let shipped = std::fs::read(rasters_dir().join(name)).unwrap();
        assert!(
            shipped == encode(&r).unwrap(),
            "{name} differs from reef_survey(): rerun regenerate_the_example_rasters"
        );
    }
}

fn survey_scene() -> Scene {
    Scene::build(&SceneSpec::preset("reef_survey_raster").unwrap(), None).unwrap()
}

/// Scene coordinates (m from the centre) of bathymetry cell (col, row from the top).
fn scene_xy(col: usize, row: usize) -> (f64, f64) {
    let (w, h, c) = BATHY;
    ((col as f64 + 0.5) * c - 0.5 * w as f64 * c, 0.5 * h as f64 * c - (row as f64 + 0.5) * c)
}

#[test]
fn a_raster_scene_takes_its_grid_place_and_crs_from_the_bathymetry() {
    let scene = survey_scene();
    assert_eq!((scene.extent.width, scene.extent.height, scene.extent.cell_m), BATHY);
    let frame = scene.frame.as_ref().unwrap();
    assert_eq!(frame.crs, Crs::Projected { epsg: UTM_56S });
    assert_eq!(frame.centre, (ORIGIN.0 + 1200.0, ORIGIN.1 - 800.0));
    // At cell centres the scene's depth is the file's value (stored to the centimetre, Float32).
    let depth = scene.depth.as_ref().unwrap();
    let land = scene.land.as_ref().unwrap();
    let mut checked = 0;
    for (col, row) in [(150, 100), (10, 10), (200, 60), (187, 140), (60, 150), (299, 199)] {
        let (x, y) = scene_xy(col, row);
        let (gx, gy) = ((col as f64 + 0.5) * 8.0, -(row as f64 + 0.5) * 8.0);
        if land.value_at(x, y) > 0.5 {
            continue;
        }
        let want = (depth_m(gx, gy) * 100.0).round() / 100.0;
        assert!((depth.value_at(x, y) - want).abs() < 1e-5, "({col}, {row}): {} vs {want}", depth.value_at(x, y));
        checked += 1;
    }
    assert_eq!(checked, 6);
    // The cay: land where the bathymetry has no data, and the scene says so.
    let (x, y) = (760.0 - 1200.0, -820.0 + 800.0);
    assert!(scene.is_land(x, y));
    assert!(!scene.is_land(0.0, 0.0));
}

#[test]
fn resampling_matches_gdalwarp() {
    if !crate::common::tool_available("gdalinfo", "gdal-bin") {
        return;
    }
    // GDAL is the independent reference: warp the 16 m habitat onto the bathymetry's 8 m grid
    // with bilinear (sand) and nearest (land) and compare every cell. Upsampling by 2 uses the
    // 2 × 2 neighbourhood in both codes, so they agree to Float32 rounding.
    let dir = tempdir("warp");
    let habitat = rasters_dir().join("reef_survey_habitat.tif");
    let scene = survey_scene();
    let sand = &scene.substrates.iter().find(|(n, _)| n == "sand").unwrap().1;
    let land = scene.land.as_ref().unwrap();
    let (w, h, c) = BATHY;
    let te = [ORIGIN.0, ORIGIN.1 - h as f64 * c, ORIGIN.0 + w as f64 * c, ORIGIN.1].map(|v| v.to_string());
    for (band, method, map) in [(2, "bilinear", sand), (4, "near", land)] {
        let out = dir.join(format!("b{band}.tif"));
        let args = ["-q", "-overwrite", "-r", method, "-tr", "8", "8", "-te", &te[0], &te[1], &te[2], &te[3]];
        run_gdal(
            "gdalwarp",
            args.iter().map(|s| s.to_string()).chain([habitat.display().to_string(), out.display().to_string()]),
        );
        let warped = read(&out).unwrap();
        assert_eq!((warped.width, warped.height), (w, h));
        let mut worst = 0.0f64;
        for row in 0..h {
            for col in 0..w {
                let (x, y) = scene_xy(col, row);
                worst = worst.max((map.value_at(x, y) - warped.bands[band - 1][row * w + col]).abs());
            }
        }
        assert!(worst < 1e-5, "band {band} ({method}): worst difference from gdalwarp {worst}");
    }
}

/// A fresh temporary directory for one test.
fn tempdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shoal-rasters-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run a GDAL tool (Debian's gdal-bin, which `.ci/run` installs) and return its stdout.
pub fn run_gdal(tool: &str, args: impl IntoIterator<Item = String>) -> String {
    let out = std::process::Command::new(tool).args(args).output().unwrap_or_else(|e| {
        panic!("{tool} does not run ({e}): install gdal-bin (`apt-get install gdal-bin`; .ci/run does)")
    });
    assert!(out.status.success(), "{tool}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// The survey scene with the rasters copied into `dir`, its RON edited by `edit`, built there.
fn build_edited(name: &str, edit: impl Fn(String) -> String, rasters: impl Fn(&Path)) -> Result<Scene, String> {
    let dir = tempdir(name);
    std::fs::create_dir_all(dir.join("rasters")).unwrap();
    for f in ["reef_survey_bathymetry.tif", "reef_survey_habitat.tif"] {
        std::fs::copy(rasters_dir().join(f), dir.join("rasters").join(f)).unwrap();
    }
    rasters(&dir);
    let text = edit(
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/scenes/reef_survey_raster.ron"))
            .unwrap(),
    );
    let spec = SceneSpec::from_ron(&text, "edited.ron").map_err(|e| e.to_string())?;
    Scene::build(&spec, Some(&dir)).map_err(|e| e.to_string())
}

#[test]
fn a_user_copy_of_the_scene_reads_its_rasters_beside_it() {
    let scene = build_edited("copy", |t| t, |_| {}).unwrap();
    assert_eq!(scene.extent.width, 300);
}

/// A broken variant of the survey scene: (name, edit of its RON, edit of its rasters, what the
/// error must say).
type Case = (&'static str, Box<dyn Fn(String) -> String>, Box<dyn Fn(&Path)>, &'static [&'static str]);

#[test]
fn raster_mistakes_are_errors_that_say_what_to_do() {
    let cases: Vec<Case> = vec![
        (
            "unit",
            Box::new(|t: String| {
                t.replace(r#"reef_survey_bathymetry.tif", unit: "m")"#, r#"reef_survey_bathymetry.tif", unit: "ft")"#)
            }),
            Box::new(|_: &Path| {}),
            &["depth_m", "unit `ft`", "`m`"],
        ),
        (
            "band",
            Box::new(|t: String| t.replace("band: 3,", "band: 7,")),
            Box::new(|_: &Path| {}),
            &["substrates.turf_algae", "band 7", "bands 1–4"],
        ),
        (
            "grid",
            Box::new(|t: String| {
                t.replace("    sun: (", "    width: 100,\n    height: 100,\n    cell_m: 8.0,\n    sun: (")
            }),
            Box::new(|_: &Path| {}),
            &["width", "300 × 200"],
        ),
        (
            // Depth without the cay as land: the bathymetry's nodata falls on water.
            "nodata",
            Box::new(|t: String| t.replace("band: 4, unit", "band: 1, unit")),
            Box::new(|_: &Path| {}),
            &["depth_m", "water cells have no data", "EPSG:32756"],
        ),
        (
            "crs",
            Box::new(|t: String| t),
            Box::new(|dir: &Path| {
                let p = dir.join("rasters/reef_survey_habitat.tif");
                let mut r = read(&p).unwrap();
                r.crs = Crs::Projected { epsg: 32755 };
                std::fs::write(&p, encode(&r).unwrap()).unwrap();
            }),
            &["EPSG:32755", "EPSG:32756", "gdalwarp"],
        ),
        (
            "degrees",
            Box::new(|t: String| t),
            Box::new(|dir: &Path| {
                let p = dir.join("rasters/reef_survey_bathymetry.tif");
                let mut r = read(&p).unwrap();
                r.crs = Crs::Geographic { epsg: 4326 };
                r.geotransform = Some([151.86, 0.0001, 0.0, -23.45, 0.0, -0.0001]);
                std::fs::write(&p, encode(&r).unwrap()).unwrap();
            }),
            &["georeference", "degrees", "gdalwarp"],
        ),
        (
            "missing",
            Box::new(|t: String| {
                t.replace("rasters/reef_survey_habitat.tif\", band: 2", "rasters/nowhere.tif\", band: 2")
            }),
            Box::new(|_: &Path| {}),
            &["substrates.sand", "nowhere.tif"],
        ),
    ];
    for (name, edit, rasters, wants) in cases {
        let e = build_edited(name, edit, rasters).err().unwrap_or_else(|| panic!("{name}: the scene built"));
        for w in wants {
            assert!(e.contains(w), "{name}: `{w}` not in: {e}");
        }
    }
}

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
    let out = super::run(&config);
    let dir = tempdir("products");
    let written = shoal::study::write_run_geotiff(&out, &dir).unwrap();
    assert!(written.files.iter().any(|f| f == "sambuca.tif"), "{:?}", written.files);
    let truth = &out.radiance.truth;
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
    let water = |(r, c): (usize, usize)| truth.land[[r, c]] == 0;
    let depth = truth.depth_m.as_ref().unwrap();
    let (mean, lo, hi) = stats(depth.indexed_iter().map(|(i, v)| (f64::from(*v), water(i))));
    let s = &bands[3];
    // GDAL sums in double the Float32 values we wrote, as we do here: agreement to rounding.
    assert!((gdal_stat(s, "MEAN") - mean).abs() < 1e-9 * mean, "{s} vs {mean}");
    assert!((gdal_stat(s, "MINIMUM") - lo).abs() < 1e-9 && (gdal_stat(s, "MAXIMUM") - hi).abs() < 1e-9);
    let land_pixels = truth.land.iter().filter(|v| **v != 0).count();
    assert!(land_pixels > 0, "the cay is in the image");
    assert_eq!(bands[7]["description"], "land (1) or water (0)");
    let land_mean = land_pixels as f64 / truth.land.len() as f64;
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
        super::small_lake(),
        shoal::instrument::InstrumentSpec::preset("nominal").unwrap(),
    );
    config.fidelity.decimation = 16;
    let out = super::run(&config);
    let dir = tempdir("local");
    shoal::study::write_run_geotiff(&out, &dir).unwrap();
    let info = gdalinfo(&dir.join("truth.tif"));
    let wkt = info["coordinateSystem"]["wkt"].as_str().unwrap();
    assert!(wkt.starts_with("ENGCRS[\"Shoal scene frame") && wkt.contains("metre"), "{wkt}");
    let back = read(&dir.join("truth.tif")).unwrap();
    assert!(matches!(back.crs, Crs::LocalMetres { .. }));
    assert_eq!(back.bands[0].len(), out.viewing.lines() * out.viewing.columns());
}

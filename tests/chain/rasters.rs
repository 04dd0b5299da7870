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
fn tempdir(name: &str) -> crate::common::TempDir {
    crate::common::TempDir::new("rasters", name)
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

mod gdal;

//! NetCDF-CF products (`--format netcdf`): the file reads back with its dimensions, band
//! coordinates, values and configuration; an independent reader of each kind opens it —
//! `ncdump -h` (Debian's netcdf-bin, the NetCDF C library) and xarray (python3-xarray with
//! python3-netcdf4) — and sees the CF metadata a scientist's script relies on.

use crate::common::Kept;
use shoal::instrument::DetectorMode;
use shoal::study::{CubeFormat, write_run_as};

use super::{run, small, small_lake};

/// A small noise-free run written as NetCDF into a fresh folder (`name`: one per test, as tests
/// run at once).
pub(crate) fn written(name: &str) -> (shoal::engine::RunOutput, tempfile_dir::Dir) {
    let mut c = shoal::engine::RunConfig::new(small_lake(), small("cubesat", 24, 16));
    c.detector = DetectorMode::IDEAL;
    let out = run(&c);
    let dir = tempfile_dir::Dir::new(name);
    let o = write_run_as(&out, dir.path(), CubeFormat::NetCdf).unwrap();
    assert!(o.files.contains(&"products.nc".to_string()), "{:?}", o.files);
    (out, dir)
}

/// A folder under the target directory, removed when dropped.
pub(crate) mod tempfile_dir {
    pub struct Dir(std::path::PathBuf);
    impl Dir {
        pub fn new(name: &str) -> Self {
            let p = std::env::temp_dir().join(format!("shoal-test-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&p);
            std::fs::create_dir_all(&p).unwrap();
            Self(p)
        }
        pub fn path(&self) -> &std::path::Path {
            &self.0
        }
    }
    impl Drop for Dir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

#[test]
fn a_netcdf_product_reads_back_with_its_bands_values_and_configuration() {
    let (out, dir) = written("netcdf-read");
    let mut reader = netcdf3::FileReader::open(dir.path().join("products.nc")).unwrap();
    let (rows, cols, nb) = out.kept().rrs.rrs.dim();
    let wavelength = reader.read_var_f32("wavelength").unwrap();
    let rrs = reader.read_var_f32("rrs").unwrap();
    let flags = reader.read_var_i32("rrs_flags").unwrap();
    let chl = reader.read_var_f32("true_chl_mg_m3").unwrap();
    let (ds, _) = reader.close();
    assert_eq!((ds.dim_size("line"), ds.dim_size("pixel"), ds.dim_size("band")), (Some(rows), Some(cols), Some(nb)));
    for (w, b) in wavelength.iter().zip(&out.response.bands.bands) {
        assert_eq!(*w, b.centre_nm as f32);
    }
    // Rrs: the run's values where valid, the fill value elsewhere.
    let fill = shoal::study::netcdf_out::FILL;
    let mut valid = 0;
    for ((v, f), (r, t)) in rrs.iter().zip(&flags).zip(out.kept().rrs.rrs.iter().zip(out.kept().rrs.flags.iter())) {
        assert_eq!(*f, i32::from(*t));
        if t & shoal::correction::RrsFlags::INVALID == 0 {
            assert_eq!(v, r);
            valid += 1;
        } else {
            assert_eq!(*v, fill);
        }
    }
    assert!(valid > rows * cols * nb / 2, "{valid}");
    assert_eq!(chl[0], out.truth.chl_mg_m3[[0, 0]]);
    assert_eq!(
        ds.get_var_attr_as_string("rrs", "standard_name").as_deref(),
        Some("surface_ratio_of_upwelling_radiance_emerging_from_sea_water_to_downwelling_radiative_flux_in_air")
    );
    let config = ds.get_global_attr_as_string("shoal_configuration").unwrap();
    assert!(config.starts_with("RunConfig(") && config.contains("cubesat"), "{}", &config[..80.min(config.len())]);
    assert_eq!(ds.get_global_attr_as_string("Conventions").as_deref(), Some("CF-1.8"));
}

#[test]
fn ncdump_reads_the_header() {
    if !crate::common::tool_available("ncdump", "netcdf-bin") {
        return;
    }
    let (_, dir) = written("netcdf-ncdump");
    // ncdump has no --version: `tool_available` only needs it to start.
    let o = std::process::Command::new("ncdump").arg("-h").arg(dir.path().join("products.nc")).output().unwrap();
    let header = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for part in [
        "band = 19 ;",
        "float rrs(line, pixel, band) ;",
        "rrs:units = \"sr-1\" ;",
        ":Conventions = \"CF-1.8\" ;",
        "rrs_flags:flag_meanings",
    ] {
        assert!(header.contains(part), "ncdump -h lacks `{part}`:\n{header}");
    }
}

#[test]
fn xarray_opens_the_product_with_its_coordinates_and_fill_values() {
    let Some(python) = crate::common::python_with("xarray, netCDF4", "python3-xarray python3-netcdf4") else { return };
    let (out, dir) = written("netcdf-xarray");
    let script = r#"
import sys, xarray as xr, numpy as np
ds = xr.open_dataset(sys.argv[1])
assert 'wavelength' in ds.coords and 'x' in ds.coords, list(ds.coords)
# The bands' names are a string coordinate.
assert 'band_name' in ds.coords and ds.band_name.values[2].decode() == sys.argv[2], ds.band_name.values
rrs = ds.rrs
assert rrs.dims == ('line', 'pixel', 'band'), rrs.dims
# The fill value became NaN; what is left is the valid Rrs.
print(int(rrs.isnull().sum()), float(np.nanmedian(rrs.isel(band=2).values)), float(ds.wavelength[2]))
"#;
    let o = std::process::Command::new(python)
        .args(["-c", script])
        .arg(dir.path().join("products.nc"))
        .arg(&out.response.bands.bands[2].name)
        .output()
        .unwrap();
    assert!(o.status.success(), "xarray: {}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let parts: Vec<f64> = text.split_whitespace().map(|v| v.parse().unwrap()).collect();
    let invalid =
        out.kept().rrs.flags.iter().filter(|f| **f & shoal::correction::RrsFlags::INVALID != 0).count() as f64;
    assert_eq!(parts[0], invalid, "NaN cells are the invalid ones");
    assert!((parts[2] - out.response.bands.bands[2].centre_nm).abs() < 1e-3, "{text}");
    assert!(parts[1] > 0.0 && parts[1] < 0.1, "median Rrs at band 3 {text}");
}

/// `shoal score` with `args`: its chl-a row's cells (it must succeed).
fn score_chl(args: &[&std::ffi::OsStr]) -> Vec<String> {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_shoal")).arg("score").args(args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = String::from_utf8_lossy(&o.stdout);
    println!("{table}");
    let row = table.lines().find(|l| l.starts_with("chl_mg_m3")).unwrap();
    row.split_whitespace().map(str::to_string).collect()
}

/// A product NetCDF of (line, pixel) maps `maps` (name, values) with a −9999 fill value.
pub(crate) fn product_file(path: &std::path::Path, shape: (usize, usize), maps: &[(&str, Vec<f32>)]) {
    let mut ds = netcdf3::DataSet::new();
    ds.add_fixed_dim("line", shape.0).unwrap();
    ds.add_fixed_dim("pixel", shape.1).unwrap();
    for (name, _) in maps {
        ds.add_var_f32(name, &["line", "pixel"]).unwrap();
        ds.add_var_attr_f32(name, "_FillValue", vec![-9999.0]).unwrap();
    }
    let mut w = netcdf3::FileWriter::open(path).unwrap();
    w.set_def(&ds, netcdf3::Version::Classic, 0).unwrap();
    for (name, values) in maps {
        w.write_var_f32(name, values).unwrap();
    }
    w.close().unwrap();
}

#[test]
fn shoal_score_scores_an_outside_product_against_the_runs_truth() {
    let (out, dir) = written("netcdf-score");
    let truth = &out.truth;
    let shape = truth.chl_mg_m3.dim();
    // An outside algorithm 10 % high everywhere, missing (fill) on land and in one pixel.
    let chl: Vec<f32> = truth
        .chl_mg_m3
        .indexed_iter()
        .map(|((r, c), v)| if truth.surface.codes()[[r, c]] != 0 || (r, c) == (0, 0) { -9999.0 } else { v * 1.1 })
        .collect();
    let product = dir.path().join("mine.nc");
    product_file(&product, shape, &[("chl_mg_m3", chl)]);
    let requirements = dir.path().join("req.ron");
    std::fs::write(&requirements, "(products: [(variable: \"chl_mg_m3\", mae_pct: Some(5))])").unwrap();
    let scored = dir.path().join("scored");
    let cells = score_chl(&[
        product.as_os_str(),
        "--truth".as_ref(),
        dir.path().as_os_str(),
        "--requirements".as_ref(),
        requirements.as_os_str(),
        "--out".as_ref(),
        scored.as_os_str(),
    ]);
    let row = cells.join(" ");
    // Log-space MAE and bias of a uniform factor 1.1 are both 10 % (Seegers et al. 2018); one
    // water pixel of the 24 × 16 image is missing.
    assert_eq!(cells[3], "10.0", "{row}");
    assert_eq!(cells[4], "+10.0", "{row}");
    let water = truth.surface.codes().iter().filter(|l| **l == 0).count();
    assert_eq!(cells[1].parse::<usize>().unwrap(), water - 1, "{row}");
    assert_eq!(cells.last().unwrap(), "FAIL", "MAE 10 % against a 5 % requirement: {row}");
    assert!(std::fs::read_to_string(scored.join("score.csv")).unwrap().contains("chl_mg_m3,"));
    // A product of another size is refused, naming both sizes.
    product_file(&product, (shape.0 + 1, shape.1), &[("chl_mg_m3", vec![1.0; (shape.0 + 1) * shape.1])]);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["score", &product.to_string_lossy(), "--truth", &dir.path().to_string_lossy(), "--out"])
        .arg(&scored)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains(&format!("{} × {}", shape.0 + 1, shape.1)) && e.contains(&format!("{} × {}", shape.0, shape.1)),
        "{e}"
    );
}

#[test]
fn the_oc4_example_runs_outside_shoal_and_is_scored() {
    let Some(python) = crate::common::python_with("xarray, netCDF4", "python3-xarray python3-netcdf4") else { return };
    let (out, dir) = written("netcdf-oc4");
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/presets/examples/oc4.py");
    let product = dir.path().join("oc4.nc");
    let o = std::process::Command::new(python)
        .arg(script)
        .arg(dir.path().join("products.nc"))
        .arg(&product)
        .output()
        .unwrap();
    assert!(o.status.success(), "oc4.py: {}", String::from_utf8_lossy(&o.stderr));
    let scored = dir.path().join("scored");
    let cells = score_chl(&[
        product.as_os_str(),
        "--truth".as_ref(),
        dir.path().as_os_str(),
        "--out".as_ref(),
        scored.as_os_str(),
    ]);
    let row = cells.join(" ");
    // Every water pixel returned, and the script's value is OC4v6 of the run's own Rrs (computed
    // here at one pixel; f32 file values, so 1e-5 relative).
    let water = out.truth.surface.codes().iter().filter(|l| **l == 0).count();
    assert_eq!(cells[1].parse::<usize>().unwrap(), water, "{row}");
    let mut reader = netcdf3::FileReader::open(&product).unwrap();
    let chl = reader.read_var_f32("chl_mg_m3").unwrap();
    let (r, c) = (8, 12);
    let cols = out.truth.surface.codes().dim().1;
    let centres = out.response.bands.centres_nm();
    let band = |nm: f64| {
        (0..centres.len()).min_by(|&a, &b| (centres[a] - nm).abs().total_cmp(&(centres[b] - nm).abs())).unwrap()
    };
    let rrs = |nm: f64| f64::from(out.kept().rrs.rrs[[r, c, band(nm)]]);
    let x = ([443.0, 490.0, 510.0].map(rrs).into_iter().fold(f64::MIN, f64::max) / rrs(555.0)).log10();
    let oc4 = 10f64.powf([0.3272, -2.9940, 2.7218, -1.2259, -0.5683].iter().rev().fold(0.0, |acc, a| acc * x + a));
    let got = f64::from(chl[r * cols + c]);
    assert!((got / oc4 - 1.0).abs() < 1e-5, "pixel ({r}, {c}): oc4.py {got}, OC4v6 {oc4}");
}

/// Files built by hand from the format's specification (`tests/fuzz/corpus/netcdf/`; `ncdump`
/// reads them as the values below): classic with a double variable and `missing_value`, 64-bit
/// offset with `_FillValue` and a NaN, and classic with `line` as the record dimension.
#[test]
fn hand_built_netcdf_files_read_as_ncdump_reads_them() {
    let corpus = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz/corpus/netcdf");
    let read = |name: &str, wanted: &[&str]| shoal::netcdf::read_maps(&corpus.join(name), wanted, 1 << 20).unwrap();
    let some = |v: &[f64]| v.iter().map(|x| Some(*x)).collect::<Vec<_>>();

    let m = read("cdf1_double_missing.nc", &["depth_m"]);
    assert_eq!(m.shape, (4, 3));
    let mut depth = some(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0]);
    depth.push(None); // 12.5 is the missing_value
    assert_eq!(m.maps, vec![("depth_m".to_string(), depth)]);

    let m = read("cdf2_maps.nc", &["chl_mg_m3", "true_chl_mg_m3", "rrs_absent"]);
    assert_eq!(m.shape, (4, 3));
    let chl = [Some(1.5), Some(2.0), None, Some(3.25), Some(0.5), None];
    assert_eq!(m.maps[0].1[..6], chl[..], "the fill value and NaN are not returned");
    assert_eq!(m.maps[0].1[6..], some(&[7.0, 8.0, 9.0, 10.0, 11.0, 12.0])[..]);
    // Written as f32 of the double i × 1.1.
    let truth: Vec<Option<f64>> = (1..=12).map(|i| Some(f64::from((f64::from(i) * 1.1) as f32))).collect();
    assert_eq!(m.maps[1].1, truth);
    assert_eq!(m.maps.len(), 2, "a wanted variable the file lacks is left out");
    assert_eq!(m.names, ["chl_mg_m3", "true_chl_mg_m3", "rrs"]);
    // A wanted variable of other dimensions is refused by name.
    let e = shoal::netcdf::read_maps(&corpus.join("cdf2_maps.nc"), &["rrs"], 1 << 20).unwrap_err();
    assert!(e.contains("`rrs`") && e.contains("line, pixel, band"), "{e}");

    let m = read("cdf1_record_line.nc", &["chl_mg_m3", "true_chl_mg_m3"]);
    assert_eq!(m.shape, (4, 3));
    let chl: Vec<f64> = (1..=12).map(f64::from).collect();
    assert_eq!(m.maps[0].1, some(&chl));
    assert_eq!(m.maps[1].1, some(&chl.iter().map(|x| 2.0 * x).collect::<Vec<_>>()));
}

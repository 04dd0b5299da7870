//! Writing runs and studies to disk: cubes as .npy, tables as CSV and JSON, figures as PNG and
//! SVG, and the resolved configuration as RON. Every file is written atomically (a temporary
//! file beside it, then a rename), so a failed or cancelled run never leaves half a file.

use std::path::Path;

use ndarray_npy::WriteNpyExt;
use serde::Serialize;

use super::figures::figure_set;
use super::{StudyError, StudyResult};
use crate::csvtext::Csv;
use crate::engine::RunOutput;

/// What was written, relative to the output directory.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outputs {
    /// File paths.
    pub files: Vec<String>,
}

impl Outputs {
    /// The figures written (the stems of `figures/*.svg`), in the order they were drawn.
    #[must_use]
    pub fn figure_names(&self) -> Vec<String> {
        self.files
            .iter()
            .filter_map(|f| f.strip_prefix("figures/").and_then(|f| f.strip_suffix(".svg")))
            .map(str::to_string)
            .collect()
    }
}

/// Write `bytes` to `path` atomically: a temporary file beside it, flushed to disk, then renamed
/// over `path`. A failure (full disk, read-only directory) removes the temporary file and names
/// the file and the reason; `path` then still holds what it held before.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), StudyError> {
    let tmp = path.with_extension(format!("{}.partial", path.extension().and_then(|e| e.to_str()).unwrap_or("")));
    let fail = |e: std::io::Error| StudyError::Io(format!("cannot write {}: {e}", path.display()));
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .map_err(|e| StudyError::Io(format!("cannot create {}: {e}", parent.display())))?;
    }
    let written = std::fs::File::create(&tmp).and_then(|mut file| write_synced(&mut file, bytes));
    written.and_then(|()| std::fs::rename(&tmp, path)).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail(e)
    })
}

/// Write everything and flush it to the device (so that the rename publishes complete data).
fn write_synced(file: &mut std::fs::File, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write as _;
    file.write_all(bytes)?;
    file.sync_all()
}

fn npy<A: WriteNpyExt + ?Sized>(dir: &Path, name: &str, array: &A, out: &mut Outputs) -> Result<(), StudyError> {
    let mut bytes = Vec::new();
    array.write_npy(&mut bytes).map_err(|e| StudyError::Io(format!("cannot encode {name}: {e}")))?;
    write_bytes(&dir.join(name), &bytes)?;
    out.files.push(name.to_string());
    Ok(())
}

fn text(dir: &Path, name: &str, content: &str, out: &mut Outputs) -> Result<(), StudyError> {
    write_bytes(&dir.join(name), content.as_bytes())?;
    out.files.push(name.to_string());
    Ok(())
}

fn json<T: Serialize>(value: &T) -> Result<String, StudyError> {
    serde_json::to_string_pretty(value).map_err(|e| StudyError::Io(format!("JSON: {e}")))
}

/// [`number`] of `v` where `known`, else an empty field.
fn some(known: bool, v: f64) -> String {
    if known { number(v) } else { String::new() }
}

fn number(v: f64) -> String {
    if !v.is_finite() {
        "inf".into()
    } else if v != 0.0 && !(1e-4..1e7).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The SNR table of a run as CSV.
#[must_use]
pub fn snr_csv(out: &RunOutput) -> String {
    let mut csv = Csv::new(&[
        "band",
        "centre_nm",
        "radiance_w_m2_sr_nm",
        "snr_analytic",
        "snr_measured",
        "signal_over_full_scale",
    ]);
    for r in out.snr.iter() {
        csv.row([
            r.band.clone(),
            number(r.centre_nm),
            number(r.radiance),
            number(r.snr_analytic),
            number(r.snr_measured),
            number(r.full_scale_fraction),
        ]);
    }
    csv.finish()
}

/// The cubes of `out`, which a writer of cubes needs: a run of an engine that does not keep
/// them ([`crate::engine::Engine::lean`]) has none, and says so.
pub(crate) fn kept_cubes(out: &RunOutput) -> Result<&crate::engine::Cubes, StudyError> {
    out.cubes.as_ref().ok_or_else(|| StudyError::Run {
        instrument: out.config.instrument.name.clone(),
        message: "the run kept no cubes to write (its engine was asked for products only)".into(),
    })
}

/// Write every product of one run into `dir`: Level-0, Level-1, Rrs, the truth, the retrievals'
/// maps, the SNR table, the report and the resolved configuration.
pub fn write_run(out: &RunOutput, dir: &Path) -> Result<Outputs, StudyError> {
    let cubes = kept_cubes(out)?;
    std::fs::create_dir_all(dir).map_err(|e| StudyError::Io(format!("cannot create {}: {e}", dir.display())))?;
    let mut o = Outputs::default();
    let r = &out.truth;
    npy(dir, "level0_dn.npy", &cubes.level0.dn, &mut o)?;
    npy(dir, "level0_flags.npy", &cubes.level0.flags, &mut o)?;
    npy(dir, "level1_radiance.npy", &cubes.level1.radiance, &mut o)?;
    npy(dir, "rrs.npy", &cubes.rrs.rrs, &mut o)?;
    npy(dir, "rrs_flags.npy", &cubes.rrs.flags, &mut o)?;
    npy(dir, "pupil_radiance.npy", &cubes.radiance.radiance, &mut o)?;
    npy(dir, "truth_rrs.npy", &*cubes.radiance.truth_rrs, &mut o)?;
    npy(dir, "truth_chl_mg_m3.npy", &r.chl_mg_m3, &mut o)?;
    npy(dir, "truth_nap_g_m3.npy", &r.nap_g_m3, &mut o)?;
    npy(dir, "truth_cdom_per_m.npy", &r.cdom_per_m, &mut o)?;
    npy(dir, "surface_class.npy", r.surface.codes(), &mut o)?;
    if let Some(d) = &r.depth_m {
        npy(dir, "truth_depth_m.npy", d, &mut o)?;
    }
    if let Some(f) = &r.substrate_fractions {
        npy(dir, "truth_substrate_fractions.npy", f, &mut o)?;
    }
    for ret in &out.retrievals {
        let p = &ret.product;
        let stem = ret.spec.name();
        for (variable, map) in p.maps() {
            npy(dir, &format!("{stem}_{variable}.npy"), map, &mut o)?;
        }
        npy(dir, &format!("{stem}_flags.npy"), &p.flags, &mut o)?;
        npy(dir, &format!("{stem}_cost.npy"), &p.cost, &mut o)?;
        if let Some(f) = &p.substrate_fractions {
            npy(dir, &format!("{stem}_substrate_fractions.npy"), f, &mut o)?;
        }
        if let Some(s) = &p.sdi {
            npy(dir, &format!("{stem}_sdi.npy"), s, &mut o)?;
        }
        if let Some(s) = &p.siop_set {
            npy(dir, &format!("{stem}_siop_set.npy"), s, &mut o)?;
        }
    }
    let tables = write_tables(out, dir)?;
    o.files.extend(tables.files);
    Ok(o)
}

/// How a run's cubes and maps are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CubeFormat {
    /// NumPy `.npy`, one array per file (the default: what the science side reads).
    #[default]
    Npy,
    /// GeoTIFF, one file per product with its bands, georeferenced ([`super::write_run_geotiff`]).
    GeoTiff,
    /// NetCDF with CF metadata, one file per run ([`super::netcdf_out`]).
    NetCdf,
}

/// Write a run's products in `format` (tables, report and configuration in both).
pub fn write_run_as(out: &RunOutput, dir: &Path, format: CubeFormat) -> Result<Outputs, StudyError> {
    match format {
        CubeFormat::Npy => write_run(out, dir),
        CubeFormat::GeoTiff => super::write_run_geotiff(out, dir),
        CubeFormat::NetCdf => {
            std::fs::create_dir_all(dir)
                .map_err(|e| StudyError::Io(format!("cannot create {}: {e}", dir.display())))?;
            let mut o = write_tables(out, dir)?;
            super::netcdf_out::write_netcdf(out, dir, &mut o)?;
            Ok(o)
        }
    }
}

/// The run's band table, SNR table, report and resolved configuration.
pub(super) fn write_tables(out: &RunOutput, dir: &Path) -> Result<Outputs, StudyError> {
    let mut o = Outputs::default();
    let mut bands = Csv::new(&["band", "centre_nm", "fwhm_nm"]);
    for b in &out.response.bands.bands {
        bands.row([b.name.clone(), number(b.centre_nm), number(b.fwhm_nm)]);
    }
    text(dir, "bands.csv", &bands.finish(), &mut o)?;
    text(dir, "snr.csv", &snr_csv(out), &mut o)?;
    text(dir, "report.json", &json(&out.report)?, &mut o)?;
    let config = out.config.to_ron().map_err(|e| StudyError::Io(e.to_string()))?;
    text(dir, "config.ron", &config, &mut o)?;
    Ok(o)
}

/// One row per run, product and variable.
#[derive(Debug, Clone, Serialize)]
struct MetricsRow<'a> {
    instrument: &'a str,
    seed: u64,
    product: &'a str,
    variable: &'a str,
    #[serde(flatten)]
    metrics: &'a crate::metrics::Metrics,
    mae_pct: f64,
    bias_pct: f64,
}

/// The metrics table as CSV: instrument, seed, product, variable, mae, bias, n, returned_pct,
/// rmse, r2 (MAE and bias as factors; mae_pct, bias_pct as percentages), and the mean absolute
/// and mean error in the product's units (`unit`: a depth error in metres).
#[must_use]
pub fn metrics_csv(result: &StudyResult) -> String {
    let mut csv = Csv::new(&[
        "instrument",
        "seed",
        "product",
        "variable",
        "mae",
        "bias",
        "mae_pct",
        "bias_pct",
        "n",
        "candidates",
        "returned_pct",
        "rmse",
        "r2",
        "mean_abs_error",
        "mean_error",
        "unit",
    ]);
    for run in &result.runs {
        for ret in &run.retrievals {
            for v in &ret.metrics.variables {
                let m = &v.metrics;
                csv.row([
                    run.label.clone(),
                    run.seed.to_string(),
                    ret.metrics.product.to_string(),
                    v.variable.to_string(),
                    // Nothing returned: no error (its sums would read MAE 0 %), an empty field.
                    some(m.n > 0, m.mae),
                    some(m.n > 0, m.bias),
                    some(m.n > 0, m.mae_pct()),
                    some(m.n > 0, m.bias_pct()),
                    m.n.to_string(),
                    m.candidates.to_string(),
                    number(m.returned_pct),
                    number(m.rmse),
                    number(m.r2),
                    number(m.mean_abs_error),
                    number(m.mean_error),
                    crate::metrics::unit(&v.variable).to_string(),
                ]);
            }
        }
    }
    csv.finish()
}

/// Write a study's tables, figures and resolved configuration into `dir` (the runs' cubes are
/// written as they finish, by [`write_run`]).
pub fn write_study(result: &StudyResult, dir: &Path, figures: bool) -> Result<Outputs, StudyError> {
    let mut o = Outputs::default();
    text(dir, "metrics.csv", &metrics_csv(result), &mut o)?;
    text(dir, "seed_spread.csv", &super::seed_spread_csv(&super::seed_spread(result)), &mut o)?;
    if let Some(r) = &result.study.spec.requirements {
        let warned: Vec<&str> =
            result.runs.iter().filter(|r| !r.report.warnings.is_empty()).map(|r| r.label.as_str()).collect();
        text(dir, "requirements.csv", &super::checks_csv(&r.check(result), &warned), &mut o)?;
    }
    let mut rows = Vec::new();
    let mut extra = Vec::new();
    for run in &result.runs {
        for ret in &run.retrievals {
            for v in &ret.metrics.variables {
                rows.push(MetricsRow {
                    instrument: &run.label,
                    seed: run.seed,
                    product: &ret.metrics.product,
                    variable: &v.variable,
                    metrics: &v.metrics,
                    mae_pct: v.metrics.mae_pct(),
                    bias_pct: v.metrics.bias_pct(),
                });
            }
            extra.push(serde_json::json!({
                "instrument": run.label,
                "seed": run.seed,
                "product": ret.metrics.product,
                "siop_sets": ret.product.siop_set_names,
                "siop_set_counts": ret.metrics.siop_set_counts,
                "siop_sets_used": ret.metrics.siop_sets_used,
                "substrate_agreement_pct": ret.metrics.substrate_agreement_pct,
                "substrate_confusion": ret.metrics.substrate_confusion,
                "depth_by_true_substrate": ret.metrics.depth_by_true_substrate,
                "failed": ret.metrics.failed,
                "failure": ret.failure,
            }));
        }
    }
    // Plausibility warnings and the truth's shares once per instrument (neither depends on the
    // noise seed).
    let (mut warnings, mut shares) = (serde_json::Map::new(), serde_json::Map::new());
    for run in &result.runs {
        warnings.entry(run.label.clone()).or_insert_with(|| serde_json::json!(run.report.warnings));
        shares.entry(run.label.clone()).or_insert_with(|| serde_json::json!(run.report.truth_shares));
    }
    let doc = serde_json::json!({
        "study": result.study.spec.name,
        "metrics": rows,
        "retrievals": extra,
        "warnings": warnings,
        "truth_shares": shares,
    });
    text(dir, "metrics.json", &json(&doc)?, &mut o)?;
    let spec = ron::ser::to_string_pretty(&result.study.spec, ron::ser::PrettyConfig::default().struct_names(true))
        .map_err(|e| StudyError::Io(format!("study RON: {e}")))?;
    text(dir, "study.ron", &spec, &mut o)?;
    if figures {
        for f in figure_set(result)? {
            write_bytes(&dir.join("figures").join(format!("{}.png", f.name)), &f.png)?;
            write_bytes(&dir.join("figures").join(format!("{}.svg", f.name)), f.svg.as_bytes())?;
            o.files.push(format!("figures/{}.png", f.name));
            o.files.push(format!("figures/{}.svg", f.name));
        }
    }
    Ok(o)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_full_disk_is_an_error_not_a_short_file() {
        // /dev/full accepts the open and fails every write with ENOSPC, as a full disk does.
        let mut full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let e = write_synced(&mut full, &[0u8; 4096]).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::StorageFull, "{e}");
    }

    #[test]
    fn an_unwritable_directory_names_the_file_and_leaves_nothing() {
        // procfs refuses new files even to root (CI runs as root, so a chmod-ed folder would not).
        let e = write_bytes(Path::new("/proc/shoal-test/figure.png"), b"png").unwrap_err().to_string();
        assert!(e.contains("/proc/shoal-test") && e.contains("cannot create"), "{e}");
        assert!(!Path::new("/proc/shoal-test").exists());
    }

    #[test]
    fn a_failed_replace_keeps_the_old_file() {
        let dir = std::env::temp_dir().join(format!("shoal-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("table.csv");
        write_bytes(&path, b"old").unwrap();
        // A directory where the temporary file would go makes the write fail after the check.
        std::fs::create_dir_all(dir.join("table.csv.partial")).unwrap();
        assert!(write_bytes(&path, b"new").is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        std::fs::remove_dir_all(dir.join("table.csv.partial")).unwrap();
        write_bytes(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 1, "{names:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

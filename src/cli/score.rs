//! `shoal score PRODUCT.nc --truth RUN_DIR`: metrics and verdicts for products made outside
//! Shoal from Shoal's simulated Rrs — a scientist's own algorithm run on the `rrs` of a
//! `--format netcdf` product, scored against the truth of the same run.
//!
//! The truth is the run's own `products.nc` (its `true_*` maps, missing on land). The product file is
//! any NetCDF-3 file with one or more (line, pixel) float variables named as Shoal's
//! (`chl_mg_m3`, `nap_g_m3`, `cdom_per_m`, `depth_m`), of the truth's size. A value that is NaN,
//! its `_FillValue`, or not positive counts as not returned. Metrics are Seegers et al. (2018)'s
//! log-space MAE and bias ([`crate::metrics::compare`]); verdicts use the requirements of the
//! study in the run folder's parent (`study.ron`), when it has any, or `--requirements FILE`.
//! Output: the table on stdout and `score.csv` in `--out`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::CliError;
use crate::metrics::{Metrics, compare};
use crate::study::Requirements;

/// Arguments of `shoal score`.
#[derive(Debug, clap::Args)]
pub struct ScoreArgs {
    /// The products to score: a NetCDF file with (line, pixel) variables named `chl_mg_m3`,
    /// `nap_g_m3`, `cdom_per_m` and/or `depth_m`.
    product: PathBuf,
    /// The run folder of `shoal study --format netcdf` (or `shoal simulate --format netcdf`)
    /// whose Rrs the products were made from: its `products.nc` holds the truth.
    #[arg(long)]
    truth: PathBuf,
    /// Requirements to judge against, a RON `Requirements` file (default: the study's in the
    /// run folder's parent, if any).
    #[arg(long)]
    requirements: Option<PathBuf>,
    /// Output directory (score.csv).
    #[arg(long, default_value = "results/score")]
    out: PathBuf,
}

/// Shoal's product variables, in table order.
const VARIABLES: [&str; 4] = crate::variable::KEYS;

/// Largest NetCDF file read, bytes: a full-resolution default-study product is ~0.7 GB.
const MAX_BYTES: u64 = 8 << 30;
/// Memory per byte of a NetCDF file read: the file's bytes, and its (line, pixel) float values
/// as `Option<f64>` (16 bytes for 4 of an f32), at most.
const HELD_PER_FILE_BYTE: f64 = 5.0;

/// Read `wanted` from `path` (see [`crate::netcdf::read_maps`]); `what` names the file in errors.
fn read_maps(path: &Path, wanted: &[&str], what: &str) -> Result<crate::netcdf::Maps, CliError> {
    crate::netcdf::read_maps(path, wanted, MAX_BYTES)
        .map_err(|m| CliError::Input(format!("{what} {}: {m}", path.display())))
}

/// `shoal score`.
pub fn run(args: &ScoreArgs) -> Result<(), CliError> {
    let truth_file = args.truth.join(crate::study::netcdf_out::FILE);
    let truth_names: Vec<String> = VARIABLES.iter().map(|v| format!("true_{v}")).collect();
    // The truth maps hold the fill value on land: land pixels are not candidates.
    let wanted: Vec<&str> = truth_names.iter().map(String::as_str).collect();
    // Both files are held at once: sized against the budget before either is read.
    let size = |p: &Path| std::fs::metadata(p).map_or(0, |m| m.len());
    let bytes = (size(&truth_file) + size(&args.product)) as f64 * HELD_PER_FILE_BYTE;
    super::within_budget(&crate::budget::Demand {
        parts: vec![crate::budget::Part {
            what: "the truth and the product, read".into(),
            bytes,
            fields: "the NetCDF files' sizes",
            lever: crate::budget::Lever::Files,
        }],
        atmosphere_s: 0.0,
    })?;
    let truth = read_maps(&truth_file, &wanted, "--truth")?;
    let product = read_maps(&args.product, &VARIABLES, "the product")?;
    if product.maps.is_empty() {
        return Err(CliError::Input(format!(
            "the product {} holds none of {} as (line, pixel) variables",
            args.product.display(),
            VARIABLES.join(", ")
        )));
    }
    if product.shape != truth.shape {
        return Err(CliError::Input(format!(
            "the product is {} × {} (line × pixel), the run's truth {} × {}",
            product.shape.0, product.shape.1, truth.shape.0, truth.shape.1
        )));
    }
    let requirements = load_requirements(args)?;
    let mut rows: Vec<(String, Metrics)> = Vec::new();
    for (name, values) in &product.maps {
        let Some((_, truth_values)) = truth.maps.iter().find(|(t, _)| *t == format!("true_{name}")) else {
            eprintln!("`{name}`: the run has no truth for it (skipped)");
            continue;
        };
        // Not returned: missing or not positive (the metrics' own rule for failed retrievals).
        let retrieved: Vec<Option<f64>> = values.iter().map(|v| v.filter(|x| *x > 0.0)).collect();
        rows.push((name.clone(), compare(&retrieved, truth_values)));
    }
    let mut table = String::new();
    let mut csv =
        crate::csvtext::Csv::new(&["variable", "n", "returned_pct", "mae_pct", "bias_pct", "rmse", "r2", "verdict"]);
    let _ = writeln!(
        table,
        "{:<12} {:>8} {:>10} {:>8} {:>8} {:>10} {:>6}  verdict",
        "variable", "n", "returned %", "MAE %", "bias %", "RMSE", "R²"
    );
    for (name, m) in &rows {
        let verdict = verdict(requirements.as_ref(), name, m);
        let _ = writeln!(
            table,
            "{:<12} {:>8} {:>10.2} {:>8.1} {:>+8.1} {:>10.4} {:>6.3}  {}",
            name,
            m.n,
            m.returned_pct,
            m.mae_pct(),
            m.bias_pct(),
            m.rmse,
            m.r2,
            verdict
        );
        csv.row([
            name.clone(),
            m.n.to_string(),
            m.returned_pct.to_string(),
            m.mae_pct().to_string(),
            m.bias_pct().to_string(),
            m.rmse.to_string(),
            m.r2.to_string(),
            verdict.to_string(),
        ]);
    }
    print!("{table}");
    let out = crate::study::OutputDir::create(&args.out, "shoal score")?;
    crate::study::write_bytes(&out.path().join("score.csv"), csv.finish().as_bytes())?;
    out.commit()?;
    eprintln!("scored {} against {} into {}", args.product.display(), truth_file.display(), args.out.display());
    Ok(())
}

/// The requirements to judge against: `--requirements`, else the study's next to the run folder.
fn load_requirements(args: &ScoreArgs) -> Result<Option<Requirements>, CliError> {
    if let Some(path) = &args.requirements {
        let text = crate::infile::read_text(path, crate::infile::RON_MAX_BYTES)
            .map_err(|e| CliError::Input(format!("--requirements {e}")))?;
        let r: Requirements =
            ron::from_str(&text).map_err(|e| CliError::Input(format!("--requirements {}: {e}", path.display())))?;
        r.validate().map_err(|e| CliError::Input(e.to_string()))?;
        return Ok(Some(r));
    }
    let study = args.truth.parent().map(|p| p.join("study.ron"));
    let Some(text) = study.and_then(|p| crate::infile::read_text(&p, crate::infile::RON_MAX_BYTES).ok()) else {
        return Ok(None);
    };
    Ok(crate::study::StudySpec::from_ron(&text, "study.ron").ok().and_then(|s| s.requirements))
}

/// pass / FAIL against the variable's requirement, or "–" without one.
fn verdict(requirements: Option<&Requirements>, variable: &str, m: &Metrics) -> &'static str {
    let Some(req) = requirements.and_then(|r| r.for_variable(variable)) else { return "–" };
    // Nothing returned: no MAE or bias to judge, which fails them (as a study's checks do).
    let judged = m.n > 0;
    let ok = req.mae_pct.is_none_or(|l| judged && m.mae_pct() <= l)
        && req.bias_pct.is_none_or(|l| judged && m.bias_pct().abs() <= l)
        && req.returned_pct.is_none_or(|l| m.returned_pct >= l);
    if ok { "pass" } else { "FAIL" }
}

//! Running a sweep (or one shard of it) on one cached engine.

use crate::control::RunControl;
use crate::engine::{Engine, EngineError};
use crate::parse::FieldError;
use crate::study::StudyError;

use super::table::{Row, Table};
use super::{ResolvedSweep, Shard, apply};

/// One run of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// Index in the sweep's fixed order.
    pub index: usize,
    /// Point index.
    pub point: usize,
    /// The parameters' values.
    pub values: Vec<f64>,
    /// Instrument (index into the study's instruments).
    pub instrument: usize,
    /// Noise seed.
    pub seed: u64,
}

/// A sweep's (or shard's) result: the table, and each run's wall time (kept apart from the
/// table so that the table depends on the inputs alone).
#[derive(Debug, Clone)]
pub struct SweepResult {
    /// The table.
    pub table: Table,
    /// (run index, seconds).
    pub seconds: Vec<(usize, f64)>,
}

/// FNV-1a, 64 bit: a fingerprint that is the same on every machine and toolchain.
pub fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

impl ResolvedSweep {
    /// The fingerprint of everything that decides the table: the sweep and every base run.
    #[must_use]
    pub fn key(&self) -> String {
        let mut text = ron::to_string(&self.spec).unwrap_or_default();
        for (label, c) in &self.bases {
            text.push_str(label);
            text.push_str(&c.to_ron().unwrap_or_default());
        }
        format!("{:016x}", fnv1a(&text))
    }
}

/// Run one job on `engine`: its rows and its wall time, s.
pub fn run_job(
    engine: &mut Engine,
    sweep: &ResolvedSweep,
    job: &Job,
    control: &RunControl,
) -> Result<(Vec<Row>, f64), StudyError> {
    let paths: Vec<&str> = sweep.spec.parameters.iter().map(|p| p.path.as_str()).collect();
    let (label, base) = &sweep.bases[job.instrument];
    let settings: Vec<(&str, f64)> = paths.iter().copied().zip(job.values.iter().copied()).collect();
    let mut config = apply(base, &settings)
        .map_err(|m| StudyError::Invalid(FieldError { field: "parameters".into(), message: m }))?;
    config.seed = job.seed;
    let start = std::time::Instant::now();
    let out = engine.run(&config, control).map_err(|e| match e {
        EngineError::Cancelled => StudyError::Cancelled,
        other => StudyError::Run { instrument: format!("{label} at {settings:?}"), message: other.to_string() },
    })?;
    let secs = start.elapsed().as_secs_f64();
    let (r, c, b) = out.report.shape;
    let saturated_pct = 100.0 * out.report.saturated as f64 / (r * c * b).max(1) as f64;
    // The measured SNR at the band-pair correction's two bands.
    let snr_pair = match config.correction.image() {
        Some(image) if image.fit == crate::correction::image::AerosolFit::BandPair => {
            image.pair(&out.response.bands.centres_nm()).ok().map(|(s, l)| {
                let at = |i: usize| out.snr.get(i).map_or(f64::NAN, |row| row.snr_measured);
                [at(s), at(l)]
            })
        }
        _ => None,
    };
    let row = |product: &str, variable: &str, mae_pct: f64, bias_pct: f64, returned_pct: f64, n: usize| Row {
        job: job.index,
        point: job.point,
        values: job.values.clone(),
        instrument: label.clone(),
        seed: job.seed,
        product: product.into(),
        variable: variable.into(),
        mae_pct,
        bias_pct,
        returned_pct,
        n,
        saturated_pct,
        snr_pair,
    };
    let mut rows = Vec::new();
    // With an image-based correction, its own error: Rrs at 400–560 nm against the truth.
    if let Some(p) = out
        .correction
        .family
        .as_ref()
        .and_then(|_| crate::correction::pooled_rrs_error(&out.correction.rrs_metrics, 400.0, 560.0))
    {
        rows.push(row("correction", "rrs_400_560", p.0, p.1, p.2, p.3));
    }
    for ret in &out.retrievals {
        for v in &ret.metrics.variables {
            let m = &v.metrics;
            // Nothing returned has no error: NaN, never the 0 % its empty sums would give.
            let (mae, bias) = if m.n > 0 { (m.mae_pct(), m.bias_pct()) } else { (f64::NAN, f64::NAN) };
            rows.push(row(&ret.metrics.product, &v.variable, mae, bias, m.returned_pct, m.n));
        }
    }
    Ok((rows, secs))
}

/// An empty table for `sweep` (its identity and columns), holding shard `shard`.
#[must_use]
pub fn empty_table(sweep: &ResolvedSweep, shard: Shard) -> Table {
    Table {
        name: sweep.spec.name.clone(),
        key: sweep.key(),
        jobs: sweep.jobs.len(),
        shard: (shard.count > 1).then_some((shard.index, shard.count)),
        parameters: sweep.spec.parameters.iter().map(|p| p.path.clone()).collect(),
        rows: Vec::new(),
    }
}

/// Run the jobs `shard` owns, in order; `on_job` hears of each as it finishes (index, seconds).
pub fn run_sweep(
    sweep: &ResolvedSweep,
    shard: Shard,
    control: &RunControl,
    mut on_job: impl FnMut(usize, f64),
) -> Result<SweepResult, StudyError> {
    let mut engine = Engine::new();
    let mut table = empty_table(sweep, shard);
    let mut seconds = Vec::new();
    for job in sweep.jobs.iter().filter(|j| shard.owns(j.index)) {
        let (rows, secs) = run_job(&mut engine, sweep, job, control)?;
        table.rows.extend(rows);
        seconds.push((job.index, secs));
        on_job(job.index, secs);
    }
    Ok(SweepResult { table, seconds })
}

//! `study` and `simulate`: resolved as the command line resolves them, run on the engine's own
//! rayon pool with the GIL released. The calling thread waits in slices of 100 ms: between them it
//! takes the GIL to call the progress callback and to check for signals, so Ctrl-C (a
//! `KeyboardInterrupt`) cancels the run at its next row, and other Python threads run meanwhile.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use clap::Parser;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use shoal::control::RunControl;
use shoal::engine::{Engine, RunConfig, RunOutput};
use shoal::retrieval::RetrievalSpec;
use shoal::retrieval::external::ExternalSpec;

use crate::errors;

/// How often the waiting thread takes the GIL: the progress callback's rate and the longest a
/// Ctrl-C waits to be seen.
const SLICE: Duration = Duration::from_millis(100);

/// Run `work` on its own thread with the GIL released; between slices call `progress` with the
/// fraction done and check for signals. A signal or an exception from the callback cancels the
/// run, waits for it to stop, and is raised.
fn released<T: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    control: &RunControl,
    fraction: impl Fn() -> f64,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    std::thread::scope(|s| {
        let (tx, mut rx) = mpsc::sync_channel(1);
        s.spawn(move || {
            let _ = tx.send(work());
        });
        let mut raised = None;
        // The fraction reported never goes back (a run's row count is announced stage by stage).
        let mut reported = 0.0_f64;
        let outcome = loop {
            // The receiver goes to the waiting closure and back (it is `Send`, not `Sync`).
            let (received, back) = py.detach(move || (rx.recv_timeout(SLICE), rx));
            rx = back;
            match received {
                Ok(out) => break Some(out),
                Err(mpsc::RecvTimeoutError::Disconnected) => break None,
                Err(mpsc::RecvTimeoutError::Timeout) => {}
            }
            if raised.is_some() {
                continue;
            }
            let step = py.check_signals().and_then(|()| match progress {
                Some(f) => {
                    reported = reported.max(fraction());
                    f.call1((reported,)).map(|_| ())
                }
                None => Ok(()),
            });
            if let Err(e) = step {
                control.cancel();
                raised = Some(e);
            }
        };
        match (raised, outcome) {
            (Some(e), _) => Err(e),
            (None, Some(out)) => Ok(out),
            (None, None) => Err(errors::panicked()),
        }
    })
}

/// Consent for each external program of `config`: given (`allow_external`) or already given in
/// this process; a registered function needs none.
fn consent(config: &RunConfig, allow_external: bool) -> PyResult<()> {
    for r in &config.retrievals {
        if let RetrievalSpec::External(e) = r {
            if allow_external && e.function.is_none() {
                shoal::retrieval::external::allow(&e.command);
            }
            if !e.may_run() {
                return Err(errors::input(
                    format!(
                        "the retrieval `{}` runs a program ({}); read the study, then pass allow_external=True to run it",
                        e.name,
                        e.what_runs()
                    ),
                    Some("retrievals"),
                ));
            }
        }
    }
    Ok(())
}

/// `config` with each `(path, value)` of `settings` set (the sweep's paths).
fn with_settings(config: &RunConfig, settings: &[(String, f64)]) -> PyResult<RunConfig> {
    let pairs: Vec<(&str, f64)> = settings.iter().map(|(p, v)| (p.as_str(), *v)).collect();
    shoal::fields::with_numbers(config, &pairs).map_err(|m| errors::input(m, None))
}

/// The engine's own pool of `threads` threads (0: one per core).
fn pool(threads: usize) -> PyResult<rayon::ThreadPool> {
    if threads > 1024 {
        return Err(errors::input(format!("threads = {threads} (allowed: 0, one per core, to 1024)"), Some("threads")));
    }
    shoal::jobs::pool(threads, "shoal-python").map_err(|e| errors::RunError::new_err(e.to_string()))
}

/// One run's products (with its cubes or not), and its retrievals' failures.
fn run_data(
    out: &RunOutput,
    cubes: bool,
) -> Result<(shoal::netcdf::InMemory, Vec<(String, String)>), shoal::study::StudyError> {
    let set = shoal::study::netcdf_out::products_in_memory(out, cubes)?;
    let failures =
        out.retrievals.iter().filter_map(|r| r.failure.clone().map(|f| (r.spec.name().to_string(), f))).collect();
    Ok((set, failures))
}

/// A retrieval function registered from Python, as a study's retrieval:
/// (name, registered function, products, bands).
type FunctionRetrieval = (String, String, Vec<String>, Option<Vec<String>>);

/// The retrieval spec that calls a registered function.
fn function_retrieval((name, function, products, bands): FunctionRetrieval) -> RetrievalSpec {
    RetrievalSpec::External(ExternalSpec {
        name,
        command: Vec::new(),
        function: Some(function),
        products,
        bands,
        time_limit_s: ExternalSpec::DEFAULT_TIME_LIMIT_S,
    })
}

/// Run a study (a built-in name, a preset of the user's library or a RON file; `None`: the
/// default study) and return its runs' products and metrics table.
#[pyfunction]
#[pyo3(signature = (study=None, *, decimation=None, seeds=None, threads=0, settings=None, functions=None, allow_external=false, progress=None, cubes=true))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn study<'py>(
    py: Python<'py>,
    study: Option<String>,
    decimation: Option<usize>,
    seeds: Option<Vec<u64>>,
    threads: usize,
    settings: Option<Vec<(String, f64)>>,
    functions: Option<Vec<FunctionRetrieval>>,
    allow_external: bool,
    progress: Option<Bound<'py, PyAny>>,
    cubes: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (mut spec, dir) = shoal::cli::study::load(study.as_deref()).map_err(errors::from_cli)?;
    if let Some(s) = seeds {
        spec.seeds = s;
    }
    spec.retrievals.extend(functions.unwrap_or_default().into_iter().map(function_retrieval));
    let mut resolved = spec.resolve(dir.as_deref()).map_err(errors::from_study)?;
    for (_, _, c) in &mut resolved.runs {
        if let Some(d) = decimation {
            c.fidelity.decimation = d;
        }
        if let Some(s) = &settings {
            *c = with_settings(c, s)?;
        }
        consent(c, allow_external)?;
    }
    let pool = pool(threads)?;
    let control = RunControl::new();
    let runs = resolved.runs.len().max(1) as f64;
    // (runs done, the control's (done, total) when the last one finished).
    let (finished, done_at, total_at) = (AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0));
    let fraction = || {
        let (done, total) = control.progress();
        let (d0, t0) = (done_at.load(Ordering::Relaxed), total_at.load(Ordering::Relaxed));
        let within = if total > t0 { (done - d0.min(done)) as f64 / (total - t0) as f64 } else { 0.0 };
        ((finished.load(Ordering::Relaxed) as f64 + within.clamp(0.0, 1.0)) / runs).min(1.0)
    };
    let work = || {
        pool.install(|| {
            let mut sets = Vec::new();
            let result = shoal::study::run_study(&resolved, &control, cubes, |i, out| {
                sets.push((i, run_data(out, cubes)?));
                let (d, t) = control.progress();
                done_at.store(d, Ordering::Relaxed);
                total_at.store(t, Ordering::Relaxed);
                finished.fetch_add(1, Ordering::Relaxed);
                Ok(())
            })?;
            Ok::<_, shoal::study::StudyError>((shoal::study::metrics_csv(&result), sets))
        })
    };
    let (metrics, sets) = released(py, progress.as_ref(), &control, fraction, work)?.map_err(errors::from_study)?;
    let out = PyDict::new(py);
    out.set_item("name", &spec.name)?;
    out.set_item("description", &spec.description)?;
    out.set_item("metrics_csv", metrics)?;
    let list = pyo3::types::PyList::empty(py);
    for (i, (set, failures)) in sets {
        let (label, seed, config) = &resolved.runs[i];
        let config = config.to_ron().map_err(|e| errors::RunError::new_err(e.to_string()))?;
        list.append((label, seed, crate::data::to_python(py, &set)?, failures, config))?;
    }
    out.set_item("runs", list)?;
    Ok(out)
}

/// `shoal simulate`'s arguments, parsed by the command line's own parser.
#[derive(Parser)]
struct Simulate {
    #[command(flatten)]
    args: shoal::cli::simulate::SimulateArgs,
}

/// Fly one instrument over one scene (`shoal simulate`'s options) and return its products.
#[pyfunction]
#[pyo3(signature = (argv, *, settings=None, functions=None, threads=0, allow_external=false, progress=None, cubes=true))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    argv: Vec<String>,
    settings: Option<Vec<(String, f64)>>,
    functions: Option<Vec<FunctionRetrieval>>,
    threads: usize,
    allow_external: bool,
    progress: Option<Bound<'py, PyAny>>,
    cubes: bool,
) -> PyResult<Bound<'py, PyDict>> {
    // `--out` is the command line's; nothing is written here.
    let argv = ["simulate".to_string()].into_iter().chain(argv).chain(["--out".into(), "-".into()]);
    let parsed = Simulate::try_parse_from(argv).map_err(|e| errors::input(e.render().to_string(), None))?;
    let mut config = shoal::cli::simulate::config_from(&parsed.args).map_err(errors::from_cli)?;
    if let Some(s) = &settings {
        config = with_settings(&config, s)?;
    }
    config.retrievals.extend(functions.unwrap_or_default().into_iter().map(function_retrieval));
    consent(&config, allow_external)?;
    let pool = pool(threads)?;
    let control = RunControl::new();
    let fraction = || {
        let (done, total) = control.progress();
        if total > 0 { (done as f64 / total as f64).min(1.0) } else { 0.0 }
    };
    // Without cubes, the engine that streams them instead of keeping them (less time and memory).
    let work = || pool.install(|| if cubes { Engine::new() } else { Engine::lean() }.run(&config, &control));
    let out = released(py, progress.as_ref(), &control, fraction, work)?.map_err(errors::from_engine)?;
    let (set, failures) = run_data(&out, cubes).map_err(errors::from_study)?;
    let dict = PyDict::new(py);
    dict.set_item("dataset", crate::data::to_python(py, &set)?)?;
    dict.set_item("failures", failures)?;
    dict.set_item("config", out.config.to_ron().map_err(|e| errors::RunError::new_err(e.to_string()))?)?;
    Ok(dict)
}

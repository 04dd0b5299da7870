//! `shoal._native`: the engine as a Python extension module (PyO3, stable ABI from Python 3.10).
//! A thin layer: it resolves studies and configurations exactly as the `shoal` command line does,
//! runs them on the engine with the GIL released, and hands back each run's products as the data
//! set `--format netcdf` writes ([`shoal::netcdf::InMemory`]), which `shoal/__init__.py` turns
//! into xarray datasets with xarray's own CF decoding. Nothing here computes physics.

mod data;
mod errors;
mod retrieval;
mod run;

use pyo3::prelude::*;

/// The module `shoal._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("InputError", m.py().get_type::<errors::InputError>())?;
    m.add("RunError", m.py().get_type::<errors::RunError>())?;
    m.add_function(wrap_pyfunction!(run::study, m)?)?;
    m.add_function(wrap_pyfunction!(run::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(presets, m)?)?;
    m.add_function(wrap_pyfunction!(preset, m)?)?;
    m.add_function(wrap_pyfunction!(ranges, m)?)?;
    m.add_function(wrap_pyfunction!(retrieval::register_retrieval, m)?)?;
    m.add_function(wrap_pyfunction!(retrieval::unregister_retrieval, m)?)?;
    Ok(())
}

/// The built-in presets by kind: `{"study": [...], "scene": [...], "instrument": [...]}`.
#[pyfunction]
fn presets(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyDict>> {
    let out = pyo3::types::PyDict::new(py);
    out.set_item("study", shoal::study::StudySpec::preset_names())?;
    out.set_item("scene", shoal::scene::SceneSpec::preset_names())?;
    out.set_item("instrument", shoal::instrument::InstrumentSpec::preset_names())?;
    Ok(out)
}

/// One preset as JSON (`kind`: `study`, `scene` or `instrument`; `name`: a built-in, a preset of
/// the user's library or a RON file, as the command line resolves it): the fields a file sets,
/// for Python to read.
#[pyfunction]
fn preset(kind: &str, name: &str) -> PyResult<String> {
    let json = match kind {
        "study" => {
            shoal::cli::study::load(Some(name)).map_err(errors::from_cli).map(|(s, _)| serde_json::to_string(&s))
        }
        "scene" => shoal::cli::simulate::scene(name).map_err(errors::from_cli).map(|(s, _)| serde_json::to_string(&s)),
        "instrument" => {
            shoal::cli::simulate::instrument(name).map_err(errors::from_cli).map(|(s, _)| serde_json::to_string(&s))
        }
        other => {
            return Err(errors::input(format!("kind `{other}` (allowed: study, scene, instrument)"), Some("kind")));
        }
    }?;
    json.map_err(|e| errors::RunError::new_err(e.to_string()))
}

/// Every numeric field's allowed values (`shoal ranges`): a list of dicts with `path`, `lo`,
/// `hi`, `lo_open`, `hi_open`, `unit`, `whole`, `meaning` and `allowed` (as the messages say it).
#[pyfunction]
fn ranges(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyList>> {
    let out = pyo3::types::PyList::empty(py);
    for r in shoal::ranges::ALL {
        let d = pyo3::types::PyDict::new(py);
        d.set_item("path", r.path)?;
        d.set_item("lo", r.lo)?;
        d.set_item("hi", r.hi)?;
        d.set_item("lo_open", r.lo_open)?;
        d.set_item("hi_open", r.hi_open)?;
        d.set_item("unit", r.unit)?;
        d.set_item("whole", r.whole)?;
        d.set_item("meaning", r.meaning)?;
        d.set_item("allowed", r.allowed())?;
        out.append(d)?;
    }
    Ok(out)
}

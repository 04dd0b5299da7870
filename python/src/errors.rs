//! Shoal's errors as Python exceptions: `InputError` (a `ValueError`: the input names a field and
//! its allowed values, as the command line's messages do) and `RunError` (a `RuntimeError`: a run
//! failed for another reason). A cancelled run raises the `KeyboardInterrupt` that cancelled it.

use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    shoal,
    InputError,
    PyValueError,
    "Invalid input: the message names the field and what is allowed."
);
pyo3::create_exception!(shoal, RunError, PyRuntimeError, "A run failed for a reason other than its input.");

/// An `InputError` with its `field` attribute (`None` when the message alone names it).
pub(crate) fn input(message: impl Into<String>, field: Option<&str>) -> PyErr {
    let err = InputError::new_err(message.into());
    Python::attach(|py| {
        let _ = err.value(py).setattr("field", field);
    });
    err
}

/// The command line's error as an exception.
pub(crate) fn from_cli(e: shoal::cli::CliError) -> PyErr {
    match e {
        shoal::cli::CliError::Input(m) => input(m, None),
        shoal::cli::CliError::Run(m) => RunError::new_err(m),
        shoal::cli::CliError::Interrupted => PyKeyboardInterrupt::new_err("cancelled"),
    }
}

/// A study's error as an exception.
pub(crate) fn from_study(e: shoal::study::StudyError) -> PyErr {
    use shoal::study::StudyError;
    match e {
        StudyError::Invalid(f) => input(f.to_string(), Some(&f.field)),
        StudyError::Cancelled => PyKeyboardInterrupt::new_err("cancelled"),
        StudyError::Io(m) => RunError::new_err(m),
        internal @ StudyError::Internal { .. } => RunError::new_err(internal.to_string()),
        other => input(other.to_string(), None),
    }
}

/// A run's error as an exception.
pub(crate) fn from_engine(e: shoal::engine::EngineError) -> PyErr {
    use shoal::engine::EngineError;
    match e {
        EngineError::Cancelled => PyKeyboardInterrupt::new_err("cancelled"),
        failed @ EngineError::Failed { .. } => input(failed.to_string(), None),
        internal => RunError::new_err(internal.to_string()),
    }
}

/// A panic on the engine's thread (a bug, never the input).
pub(crate) fn panicked() -> PyErr {
    PyRuntimeError::new_err("the engine's thread panicked (a bug in Shoal: please report it)")
}

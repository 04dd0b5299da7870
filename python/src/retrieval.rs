//! Python callables as retrievals: registered under a name ([`shoal::retrieval::function`]), run
//! on the engine's thread with the GIL taken for the call. The callable is `shoal`'s bridge
//! (`shoal/__init__.py`), which builds the xarray dataset an external program would read from the
//! input the engine hands over, calls the scientist's function, and returns each product as
//! `(bytes of little-endian float64, (lines, pixels))`. Both directions are copies: no buffer is
//! lent across.

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use shoal::netcdf::{InMemory, Maps};

/// The maps of the bridge's answer, checked: a dict of `name -> (bytes, (lines, pixels))`.
fn maps_of(answer: &Bound<'_, PyAny>) -> Result<Maps, String> {
    let dict = answer.cast::<PyDict>().map_err(|_| "the bridge did not return a dict".to_string())?;
    let mut maps = Vec::new();
    let mut names = Vec::new();
    let mut shape = None;
    for (k, v) in dict.iter() {
        let name = k.extract::<String>().map_err(|e| e.to_string())?;
        let (bytes, dims) =
            v.extract::<(Bound<'_, PyBytes>, (usize, usize))>().map_err(|e| format!("`{name}`: {e}"))?;
        let raw = bytes.as_bytes();
        if raw.len() != dims.0 * dims.1 * 8 {
            return Err(format!("`{name}`: {} bytes for {} × {} float64 values", raw.len(), dims.0, dims.1));
        }
        if shape.is_some_and(|s| s != dims) {
            return Err(format!("`{name}` is {} × {}, another product {:?}", dims.0, dims.1, shape));
        }
        shape = Some(dims);
        let values = raw
            .chunks_exact(8)
            .map(|c| {
                let mut b = [0u8; 8];
                b.copy_from_slice(c);
                Some(f64::from_le_bytes(b)).filter(|v| v.is_finite())
            })
            .collect();
        names.push(name.clone());
        maps.push((name, values));
    }
    Ok(Maps { shape: shape.unwrap_or((0, 0)), maps, names })
}

/// Register `bridge` (a callable taking the input as [`crate::data`]'s dict) under `name`; a
/// function of that name is replaced. A study's retrieval `External((..., function: name))` calls it.
#[pyfunction]
pub(crate) fn register_retrieval(name: String, bridge: Py<PyAny>) -> u64 {
    let bridge = Arc::new(bridge);
    let function = move |input: &InMemory, _control: &shoal::control::RunControl| -> Result<Maps, String> {
        Python::attach(|py| {
            let raw = crate::data::to_python(py, input).map_err(|e| e.to_string())?;
            let answer = bridge.call1(py, (raw,)).map_err(|e| describe(py, &e))?;
            maps_of(answer.bind(py))
        })
    };
    shoal::retrieval::function::register(&name, Arc::new(function))
}

/// Forget the retrieval function registered as `name`.
#[pyfunction]
pub(crate) fn unregister_retrieval(name: &str) {
    shoal::retrieval::function::unregister(name);
}

/// A Python exception as one message: its type, its text and the last line of its traceback.
fn describe(py: Python<'_>, e: &PyErr) -> String {
    let place = e
        .traceback(py)
        .and_then(|t| t.format().ok())
        .and_then(|t| t.lines().rev().find(|l| l.trim_start().starts_with("File")).map(|l| l.trim().to_string()))
        .map(|l| format!(" ({l})"))
        .unwrap_or_default();
    format!("{}{place}", e.value(py).repr().map_or_else(|_| e.to_string(), |r| r.to_string()))
}

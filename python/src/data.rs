//! A data set held in memory ([`InMemory`]: what a NetCDF file of Shoal's holds) as plain Python
//! objects, for `shoal/__init__.py` to turn into an xarray dataset with xarray's own CF decoding:
//!
//! ```text
//! {"dims": [(name, size), ...],
//!  "attrs": [(name, value), ...],
//!  "variables": [(name, (dim, ...), [(attr, value), ...], dtype, bytearray), ...]}
//! ```
//!
//! An attribute's value is a `str`, or `(dtype, [numbers])` for numeric attributes; `dtype` is a
//! NumPy type string (`"<f4"`, `"<i4"`, `"S1"` for characters). Values are copied into a
//! `bytearray` Python owns: no buffer of Rust's is ever lent to Python, and none of Python's to
//! the engine's threads.

use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyDict, PyList, PyTuple};
use shoal::netcdf::{AttrValue, Column, InMemory};

/// `(name, value)` attribute pairs as a Python list.
fn attrs<'py>(py: Python<'py>, attrs: &[(String, AttrValue)]) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for (name, value) in attrs {
        let value: Bound<'py, PyAny> = match value {
            AttrValue::Text(t) => t.into_pyobject(py)?.into_any(),
            AttrValue::Float(v) => ("<f4", v.clone()).into_pyobject(py)?.into_any(),
            AttrValue::Int(v) => ("<i4", v.clone()).into_pyobject(py)?.into_any(),
        };
        out.append((name, value))?;
    }
    Ok(out)
}

/// Little-endian bytes of `values`, written straight into a new `bytearray`.
fn bytes_of<'py, T: Copy, const N: usize>(
    py: Python<'py>,
    values: &[T],
    to_le: impl Fn(T) -> [u8; N],
) -> PyResult<Bound<'py, PyByteArray>> {
    PyByteArray::new_with(py, values.len() * N, |buf| {
        for (chunk, &v) in buf.chunks_exact_mut(N).zip(values) {
            chunk.copy_from_slice(&to_le(v));
        }
        Ok(())
    })
}

/// `set` as the dict the module documentation describes.
pub(crate) fn to_python<'py>(py: Python<'py>, set: &InMemory) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("dims", set.dims.clone())?;
    out.set_item("attrs", attrs(py, &set.attrs)?)?;
    let variables = PyList::empty(py);
    for v in &set.variables {
        let (dtype, data) = match &v.values {
            Column::Float(x) => ("<f4", bytes_of(py, x, f32::to_le_bytes)?),
            Column::Int(x) => ("<i4", bytes_of(py, x, i32::to_le_bytes)?),
            Column::Text(x) => ("S1", PyByteArray::new(py, x)),
        };
        let dims = PyTuple::new(py, &v.dims)?;
        variables.append((v.name.as_str(), dims, attrs(py, &v.attrs)?, dtype, data))?;
    }
    out.set_item("variables", variables)?;
    Ok(out)
}

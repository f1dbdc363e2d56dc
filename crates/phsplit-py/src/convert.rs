//! Values between Python and TOML: a Python mapping as a TOML table (the form every vessel
//! file and `[simulation]` table takes in the core), a TOML value back as Python, and numpy
//! arrays as plain vectors.

use crate::InvalidInputError;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use toml::{Table, Value};

/// A Python value as TOML (mappings, sequences, bool, int, float, str); `path` names it in
/// the error.
pub(crate) fn to_toml(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<Value> {
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => Ok(Value::Integer(i)),
            Err(_) => Ok(Value::Float(obj.extract()?)),
        };
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(obj.extract()?));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        return Ok(Value::Table(to_table(d, path)?));
    }
    if obj.is_instance_of::<PyList>()
        || obj.is_instance_of::<PyTuple>()
        || obj.hasattr("__array__")?
    {
        // numpy scalars have __array__ too: a 0-d array is a number.
        if let Ok(x) = obj.extract::<f64>() {
            if !obj.is_instance_of::<PyList>() && !obj.is_instance_of::<PyTuple>() {
                return Ok(Value::Float(x));
            }
        }
        let items: Vec<Bound<'_, PyAny>> = obj.try_iter()?.collect::<PyResult<_>>()?;
        return Ok(Value::Array(
            items
                .iter()
                .enumerate()
                .map(|(i, v)| to_toml(v, &format!("{path}[{i}]")))
                .collect::<PyResult<_>>()?,
        ));
    }
    if obj.is_none() {
        // TOML has no null: a key is given a value or left out.
        return Err(InvalidInputError::new_err(format!(
            "{path} is None: give it a value or leave the key out (a file has no null; an optional key left out takes its default)"
        )));
    }
    Err(InvalidInputError::new_err(format!(
        "{path} must be a number, a string, a boolean, a sequence or a mapping, got {}",
        obj.get_type().name()?
    )))
}

pub(crate) fn to_table(d: &Bound<'_, PyDict>, path: &str) -> PyResult<Table> {
    let mut t = Table::new();
    for (k, v) in d.iter() {
        let key: String = k.extract().map_err(|_| {
            InvalidInputError::new_err(format!("the keys of {path} must be strings"))
        })?;
        let sub = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{key}")
        };
        t.insert(key, to_toml(&v, &sub)?);
    }
    Ok(t)
}

/// A TOML value as Python (tables → dict, arrays → list).
pub(crate) fn from_toml<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        Value::Float(f) => f.into_pyobject(py)?.into_any(),
        Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(from_toml(py, x)?)?;
            }
            l.into_any()
        }
        Value::Table(t) => {
            let d = PyDict::new(py);
            for (k, x) in t {
                d.set_item(k, from_toml(py, x)?)?;
            }
            d.into_any()
        }
        Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
    })
}

/// The entries of a 1-D array, contiguous or strided.
pub(crate) fn entries(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

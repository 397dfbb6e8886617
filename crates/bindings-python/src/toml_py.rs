//! A TOML value (the tissue file's, through serde) as Python objects: tables as dicts,
//! arrays as lists, the scalars as themselves (datetimes as their text).
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use pyo3::IntoPyObjectExt;

/// `v` as a Python object.
pub fn to_py_object<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    match v {
        toml::Value::String(s) => s.into_bound_py_any(py),
        toml::Value::Integer(i) => i.into_bound_py_any(py),
        toml::Value::Float(f) => f.into_bound_py_any(py),
        toml::Value::Boolean(b) => b.into_bound_py_any(py),
        toml::Value::Datetime(d) => d.to_string().into_bound_py_any(py),
        toml::Value::Array(a) => {
            let list = PyList::empty(py);
            for item in a {
                list.append(to_py_object(py, item)?)?;
            }
            Ok(list.into_any())
        }
        toml::Value::Table(t) => {
            let dict = PyDict::new(py);
            for (k, item) in t {
                dict.set_item(k, to_py_object(py, item)?)?;
            }
            Ok(dict.into_any())
        }
    }
}

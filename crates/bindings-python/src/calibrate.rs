//! `calibrate`: `needle calibrate` (needle-calibrate) from Python: a measured axial force
//! against needle position (a CSV file, or two arrays) in, the fitted tissue stack and
//! its residuals out (`calibration::Calibration`). A bad curve raises `CurveError` with
//! the row and column.
use crate::calibration::Calibration;
use needle_calibrate::events::EventRule;
use needle_calibrate::measured::{self, CurveError as BadCurve};
use needle_calibrate::Options;
use numpy::{PyArray1, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::path::{Path, PathBuf};

pyo3::create_exception!(
    needle_haptics,
    CurveError,
    PyValueError,
    "A measured curve the calibration cannot take. `row` (0-based data row), `column` (position_mm or force_n) and `line` (1-based line of the CSV file) say where; None when not known or not one place."
);

/// A Python error for a calibration error: `CurveError` with row, column and line when
/// the curve was refused at a known place, else `ValueError`.
fn to_py(py: Python<'_>, e: &anyhow::Error) -> PyErr {
    let message = format!("{e:#}");
    let Some(at) = e.downcast_ref::<BadCurve>() else {
        return PyValueError::new_err(message);
    };
    let err = CurveError::new_err(message);
    let value = err.value(py);
    // setting attributes on a fresh exception only fails on memory exhaustion; the
    // message still says where
    let _ = value.setattr("row", at.row);
    let _ = value.setattr("column", at.column);
    let _ = value.setattr("line", at.line);
    err
}

/// One column of numbers: a 1-D float64 array (anything else is refused with how to
/// convert it).
fn column(py: Python<'_>, v: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<f64>> {
    let refuse = |what: String| {
        let err = CurveError::new_err(format!("{name} {what}: np.asarray({name}, dtype=np.float64) makes a 1-D float64 array"));
        let _ = err.value(py).setattr("column", name);
        err
    };
    let Ok(untyped) = v.cast::<PyUntypedArray>() else {
        let ty = v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into());
        return Err(refuse(format!("is a {ty}, not a numpy.ndarray")));
    };
    if untyped.ndim() != 1 {
        return Err(refuse(format!("has shape {:?}, not (n,)", untyped.shape())));
    }
    let Ok(typed) = v.cast::<PyArray1<f64>>() else {
        return Err(refuse(format!("has dtype {}, not float64", untyped.dtype())));
    };
    Ok(typed.try_readonly().map_err(|e| refuse(format!("is being written elsewhere: {e}")))?.as_array().to_vec())
}

/// The measured points of `curve`: a path (str or os.PathLike) to a CSV file with
/// columns position_mm and force_n, or a tuple (position_mm, force_n) of arrays; with
/// the name that labels them.
fn points(py: Python<'_>, curve: &Bound<'_, PyAny>, label: Option<String>) -> PyResult<(Vec<measured::Point>, PathBuf)> {
    if let Ok(pair) = curve.cast::<PyTuple>() {
        let (Ok(p), Ok(f), 2) = (pair.get_item(0), pair.get_item(1), pair.len()) else {
            return Err(PyValueError::new_err(format!("curve is a tuple of {}: give (position_mm, force_n)", pair.len())));
        };
        let (p, f) = (column(py, &p, measured::COLUMNS[0])?, column(py, &f, measured::COLUMNS[1])?);
        let pts = measured::from_columns(&p, &f).map_err(|e| to_py(py, &e))?;
        return Ok((pts, PathBuf::from(label.unwrap_or_else(|| "arrays".into()))));
    }
    let Ok(path) = curve.extract::<PathBuf>() else {
        return Err(PyValueError::new_err(
            "curve must be a path to a CSV file (str or os.PathLike) or a tuple (position_mm, force_n) of float64 arrays",
        ));
    };
    let pts = measured::read_curve(&path).map_err(|e| to_py(py, &e))?;
    Ok((pts, label.map_or(path, PathBuf::from)))
}

/// Fits a tissue stack to a measured axial force against needle position, as `needle
/// calibrate` does, against the set compiled in (its FE surrogate, insertion model and
/// `campaign.toml`'s shear modulus for the track stiffness).
#[pyfunction]
#[pyo3(signature = (curve, /, *, name, needle_diameter_mm, speed_mm_per_s, drop_fraction = EventRule::default().drop_fraction, label = None))]
pub fn calibrate(
    py: Python<'_>,
    curve: &Bound<'_, PyAny>,
    name: String,
    needle_diameter_mm: f64,
    speed_mm_per_s: f64,
    drop_fraction: f64,
    label: Option<String>,
) -> PyResult<Calibration> {
    let set = Path::new(needle_haptics::model_info::SET_DIR);
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(set).map_err(|e| PyValueError::new_err(e.to_string()))?.ok_or_else(|| {
        PyValueError::new_err(format!("{}: no campaign.toml: the FE tissue's shear modulus sets the track stiffness", set.display()))
    })?;
    let (points, curve_name) = points(py, curve, label)?;
    let opts = Options {
        curve: &curve_name,
        name,
        needle_diameter_mm,
        speed_mm_per_s,
        rule: EventRule { drop_fraction, ..EventRule::default() },
        fe_shear_modulus_n_per_mm2: mu0,
    };
    let c = py.detach(|| needle_calibrate::calibrate_points(&opts, points)).map_err(|e| to_py(py, &e))?;
    Calibration::new(py, &c)
}

//! `Calibration`: what `calibrate` returns, as Python values and NumPy arrays: the
//! tissue stack (the file's text and its values), the measured curve, the model along it
//! and the residuals, the punctures, the checks.
use crate::toml_py::to_py_object;
use needle_calibrate::Calibration as Result;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The result of `calibrate`.
#[pyclass(module = "needle_haptics._native", frozen, get_all)]
pub struct Calibration {
    /// The tissue file's text, as `needle calibrate` writes it (without its comment header).
    toml: String,
    /// The same stack as a dict (the file's keys: format, name, description,
    /// needle_diameter_mm, layer: a list of dicts).
    stack: Py<PyDict>,
    /// Needle position of contact (depth 0), mm.
    onset_mm: f64,
    /// Measured needle over the FE needle (geometric similarity factor).
    similarity: f64,
    /// float64 (m,): the measured needle positions, mm, in the curve's order.
    position_mm: Py<PyArray1<f64>>,
    /// float64 (m,): the measured axial force, N.
    force_n: Py<PyArray1<f64>>,
    /// float64 (m,): the calibrated stack's force at each measured position (the
    /// insertion model's tick nearest it), N.
    model_force_n: Py<PyArray1<f64>>,
    /// float64 (m,): force_n - model_force_n, N.
    residual_n: Py<PyArray1<f64>>,
    /// float64 (t, 2): the model per tick at 1 kHz: needle position mm, axial force N.
    replay: Py<PyArray2<f64>>,
    /// float64 (k, 2): the measured punctures (position mm, peak force N).
    measured_punctures: Py<PyArray2<f64>>,
    /// float64 (k', 2): the model's punctures (position mm, force N just before).
    model_punctures: Py<PyArray2<f64>>,
    /// The checks against the curve: dicts with what, measured, model, error, goal,
    /// unit, met.
    checks: Py<PyList>,
    /// Whether every check is met (`needle calibrate` exits 1 otherwise).
    all_met: bool,
}

fn pairs<'py>(py: Python<'py>, rows: &[(f64, f64)]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows: Vec<Vec<f64>> = rows.iter().map(|&(a, b)| vec![a, b]).collect();
    if rows.is_empty() {
        return Ok(PyArray2::zeros(py, [0, 2], false));
    }
    PyArray2::from_vec2(py, &rows).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

impl Calibration {
    pub fn new(py: Python<'_>, c: &Result) -> PyResult<Self> {
        let stack = to_py_object(py, &toml::Value::try_from(&c.stack).map_err(|e| PyRuntimeError::new_err(e.to_string()))?)?;
        let stack = stack.cast_into::<PyDict>().map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        let position: Vec<f64> = c.points.iter().map(|p| p.position_mm).collect();
        let force: Vec<f64> = c.points.iter().map(|p| p.force_n).collect();
        let model: Vec<f64> = position.iter().map(|&p| c.replay.at(p)).collect();
        let residual: Vec<f64> = force.iter().zip(&model).map(|(f, m)| f - m).collect();
        let measured_peaks: Vec<(f64, f64)> =
            c.events.iter().filter_map(|e| c.points.get(e.peak)).map(|p| (p.position_mm, p.force_n)).collect();
        let checks = PyList::empty(py);
        for k in &c.checks {
            let d = PyDict::new(py);
            d.set_item("what", &k.what)?;
            d.set_item("measured", k.measured)?;
            d.set_item("model", k.model)?;
            d.set_item("error", k.error)?;
            d.set_item("goal", k.goal)?;
            d.set_item("unit", k.unit)?;
            d.set_item("met", k.met())?;
            checks.append(d)?;
        }
        Ok(Self {
            toml: c.stack.to_toml(""),
            stack: stack.unbind(),
            onset_mm: c.fit.onset_mm,
            similarity: c.similarity,
            position_mm: PyArray1::from_vec(py, position).unbind(),
            force_n: PyArray1::from_vec(py, force).unbind(),
            model_force_n: PyArray1::from_vec(py, model).unbind(),
            residual_n: PyArray1::from_vec(py, residual).unbind(),
            replay: pairs(py, &c.replay.samples)?.unbind(),
            measured_punctures: pairs(py, &measured_peaks)?.unbind(),
            model_punctures: pairs(py, &c.replay.punctures)?.unbind(),
            checks: checks.unbind(),
            all_met: c.checks.iter().all(needle_calibrate::replay::Check::met),
        })
    }
}

//! `needle_haptics._native`: the library's f32 evaluators and insertion model over NumPy
//! arrays. The Python package `needle_haptics` (python/) re-exports it and adds the
//! set's FE data and a NumPy-only reference of the model.
//!
//! Every function takes the poses as a `float32` array of shape `(n, 5)` (columns
//! `x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm`, any strides: read in place, never
//! copied) and writes only its output arrays. A bad array raises `PoseError` (a
//! `ValueError`) naming the row and column.
use pyo3::prelude::*;

mod calibrate;
mod calibration;
mod eval;
mod info;
mod insertion;
mod poses;
mod rows;
mod sample;
mod toml_py;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("PoseError", m.py().get_type::<poses::PoseError>())?;
    m.add_function(wrap_pyfunction!(eval::wrench, m)?)?;
    m.add_function(wrap_pyfunction!(eval::wrench_and_stiffness, m)?)?;
    m.add_class::<insertion::Insertion>()?;
    m.add("CurveError", m.py().get_type::<calibrate::CurveError>())?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate, m)?)?;
    m.add_class::<calibration::Calibration>()?;
    m.add_function(wrap_pyfunction!(sample::sample_stack, m)?)?;
    info::add(m)?;
    Ok(())
}

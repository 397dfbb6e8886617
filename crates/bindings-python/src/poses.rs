//! The pose array: its checks (array, dtype, shape, finite values) and the errors that
//! name the row and column.
use needle_haptics::Pose;
use numpy::ndarray::ArrayView2;
use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The pose columns, in order.
pub const COLUMNS: [&str; 5] = ["x_mm", "z_mm", "theta_x_deg", "theta_z_deg", "depth_mm"];

pyo3::create_exception!(
    needle_haptics,
    PoseError,
    PyValueError,
    "A pose array the library cannot take: not a float32 ndarray of shape (n, 5), or a value that is NaN or infinite. `row` and `column` say where (None when the whole array is wrong)."
);

/// A `PoseError` with `row` and `column` attributes (either may be None).
pub fn pose_error(py: Python<'_>, message: String, row: Option<usize>, column: Option<usize>) -> PyErr {
    let err = PoseError::new_err(message);
    let value = err.value(py);
    // Setting attributes on a fresh exception instance only fails on memory exhaustion;
    // the message alone still says where.
    let _ = value.setattr("row", row);
    let _ = value.setattr("column", column);
    err
}

/// `poses` checked to be a float32 ndarray of shape (n, 5), borrowed read-only.
pub fn borrow<'py>(poses: &Bound<'py, PyAny>, what: &str) -> PyResult<PyReadonlyArray2<'py, f32>> {
    let py = poses.py();
    let Ok(untyped) = poses.cast::<PyUntypedArray>() else {
        let ty = poses.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into());
        return Err(pose_error(
            py,
            format!(
                "{what} must be a numpy.ndarray of float32 with shape (n, 5), got a {ty} (np.asarray({what}, dtype=np.float32) makes one)"
            ),
            None,
            None,
        ));
    };
    let shape = untyped.shape();
    if shape.len() != 2 {
        return Err(pose_error(py, format!("{what} must have 2 dimensions (n, 5), got shape {shape:?}"), None, None));
    }
    if shape.get(1) != Some(&COLUMNS.len()) {
        let got = shape.get(1).copied().unwrap_or(0);
        let column = if got > COLUMNS.len() { Some(COLUMNS.len()) } else { Some(got) };
        return Err(pose_error(
            py,
            format!(
                "{what} has {got} columns, the pose has 5 ({}): column {} is {}",
                COLUMNS.join(", "),
                column.unwrap_or(0),
                if got > 5 { "one too many" } else { "missing" }
            ),
            None,
            column,
        ));
    }
    let Ok(typed) = poses.cast::<PyArray2<f32>>() else {
        return Err(wrong_dtype(poses, untyped, what));
    };
    typed.try_readonly().map_err(|e| pose_error(py, format!("{what} is being written elsewhere: {e}"), None, None))
}

/// The pose at `row` of a checked view.
#[inline]
pub fn pose_at(view: &ArrayView2<'_, f32>, row: usize) -> Pose {
    let r = view.row(row);
    let v = |c: usize| r.get(c).copied().unwrap_or(f32::NAN);
    Pose::new(v(0), v(1), v(2), v(3), v(4))
}

/// The error for the first value of `row` that is not finite (the library's ERROR bit
/// for that row).
pub fn not_finite(py: Python<'_>, view: &ArrayView2<'_, f32>, row: usize, what: &str) -> PyErr {
    let r = view.row(row);
    let column = r.iter().position(|v| !v.is_finite());
    match column.and_then(|c| Some((c, *r.get(c)?, COLUMNS.get(c)?))) {
        Some((c, v, name)) => {
            pose_error(py, format!("{what}[{row}, {c}] ({name}) is {v}: every pose value must be finite"), Some(row), Some(c))
        }
        None => pose_error(
            py,
            format!("{what}[{row}]: the library reports an error for this pose (no fitted model in this build?)"),
            Some(row),
            None,
        ),
    }
}

/// The error for an array of another dtype: for float64, the first value that float32
/// cannot hold exactly (row and column), else what converting would do.
fn wrong_dtype(poses: &Bound<'_, PyAny>, untyped: &Bound<'_, PyUntypedArray>, what: &str) -> PyErr {
    let py = poses.py();
    let dtype = untyped.dtype();
    let fix = format!("{what}.astype(np.float32) converts");
    let Ok(wide) = poses.cast::<PyArray2<f64>>().map(|a| a.try_readonly()) else {
        return pose_error(py, format!("{what} has dtype {dtype}, the library takes float32: {fix}"), None, None);
    };
    let Ok(wide) = wide else {
        return pose_error(py, format!("{what} has dtype {dtype}, the library takes float32: {fix}"), None, None);
    };
    let view = wide.as_array();
    let inexact = view.indexed_iter().find(|(_, v)| f64::from(**v as f32).to_bits() != v.to_bits() && !v.is_nan());
    match inexact {
        Some(((row, c), v)) => pose_error(
            py,
            format!(
                "{what} has dtype float64, the library takes float32 (its own bits): {what}[{row}, {c}] ({}) = {v:?} is not a float32 value (nearest {:?}); {fix}",
                COLUMNS.get(c).copied().unwrap_or("?"),
                *v as f32
            ),
            Some(row),
            Some(c),
        ),
        None => pose_error(py, format!("{what} has dtype float64, the library takes float32; every value is a float32 value: {fix} without rounding"), None, None),
    }
}

//! `wrench` and `wrench_and_stiffness` over a pose array: one library call per row,
//! outside the GIL, row-parallel (`rows`), into freshly allocated output arrays (the only
//! allocation).
use crate::poses::{borrow, not_finite};
use crate::rows::for_each_row;
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

fn contiguous<T>(slice: Option<&mut [T]>) -> PyResult<&mut [T]> {
    slice.ok_or_else(|| PyRuntimeError::new_err("a freshly allocated output array is not contiguous"))
}

/// The wrench at every pose: `(wrench, status)`, `wrench` float32 `(n, 6)` (fx_n, fy_n,
/// fz_n in N; mx_nmm, my_nmm, mz_nmm in N·mm about the hub), `status` uint8 `(n,)`
/// (saturation bits). The library's bits (`needle_haptics::wrench`).
#[pyfunction]
#[pyo3(signature = (poses, /))]
#[allow(clippy::type_complexity)]
pub fn wrench<'py>(poses: &Bound<'py, PyAny>) -> PyResult<(Bound<'py, PyArray2<f32>>, Bound<'py, PyArray1<u8>>)> {
    let py = poses.py();
    let input = borrow(poses, "poses")?;
    let view = input.as_array();
    let n = view.nrows();
    let wrench_out = PyArray2::<f32>::zeros(py, [n, 6], false);
    let status_out = PyArray1::<u8>::zeros(py, [n], false);
    let first_error = {
        let (mut w, mut s) = (wrench_out.readwrite(), status_out.readwrite());
        let (w, s) = (contiguous(w.as_slice_mut().ok())?, contiguous(s.as_slice_mut().ok())?);
        py.detach(|| {
            for_each_row(&view, w, &mut [], 0, s, |pose, w, _| {
                let e = needle_haptics::wrench(pose);
                w.copy_from_slice(&e.wrench.to_array());
                e.status.bits()
            })
        })
    };
    match first_error {
        Some(row) => Err(not_finite(py, &view, row, "poses")),
        None => Ok((wrench_out, status_out)),
    }
}

/// The wrench and its stiffness at every pose: `(wrench, stiffness, status)`;
/// `stiffness` float32 `(n, 3, 6)`: d wrench / d depth_mm, d x_mm, d z_mm (N/mm and
/// N·mm/mm), each in the wrench's component order. The library's bits
/// (`needle_haptics::wrench_and_stiffness`).
#[pyfunction]
#[pyo3(signature = (poses, /))]
#[allow(clippy::type_complexity)]
pub fn wrench_and_stiffness<'py>(
    poses: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyArray2<f32>>, Bound<'py, PyArray3<f32>>, Bound<'py, PyArray1<u8>>)> {
    let py = poses.py();
    let input = borrow(poses, "poses")?;
    let view = input.as_array();
    let n = view.nrows();
    let wrench_out = PyArray2::<f32>::zeros(py, [n, 6], false);
    let stiffness_out = PyArray3::<f32>::zeros(py, [n, 3, 6], false);
    let status_out = PyArray1::<u8>::zeros(py, [n], false);
    let first_error = {
        let (mut w, mut k, mut s) = (wrench_out.readwrite(), stiffness_out.readwrite(), status_out.readwrite());
        let (w, k, s) = (contiguous(w.as_slice_mut().ok())?, contiguous(k.as_slice_mut().ok())?, contiguous(s.as_slice_mut().ok())?);
        py.detach(|| {
            for_each_row(&view, w, k, 18, s, |pose, w, k| {
                let e = needle_haptics::wrench_and_stiffness(pose);
                w.copy_from_slice(&e.wrench.to_array());
                let rates = [e.stiffness.by_depth.to_array(), e.stiffness.by_x.to_array(), e.stiffness.by_z.to_array()];
                k.copy_from_slice(rates.as_flattened());
                e.status.bits()
            })
        })
    };
    match first_error {
        Some(row) => Err(not_finite(py, &view, row, "poses")),
        None => Ok((wrench_out, stiffness_out, status_out)),
    }
}

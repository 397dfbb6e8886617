//! `Insertion`: the library's whole-insertion model (`needle_haptics::insertion`) through
//! a compiled-in tissue stack or a tissue file loaded at run time (checked as the build
//! checks a compiled-in one: `needle_calibrate::runtime_stack`), one tick per pose row.
use crate::poses::{borrow, not_finite, pose_at};
use needle_calibrate::runtime_stack::OwnedStack;
use needle_haptics::insertion::{Insertion as Model, InsertionConfig};
use needle_haptics::Status;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The outputs of `Insertion.run`, one row per tick.
#[pyclass(module = "needle_haptics._native", frozen, get_all)]
pub struct Trajectory {
    /// float32 (n, 6): the wrench on the needle (N, N·mm about the hub).
    wrench: Py<PyArray2<f32>>,
    /// uint8 (n,): the surrogate's status bits.
    status: Py<PyArray1<u8>>,
    /// uint16 (n,): the phase code (0 approach, 0x100|layer deflecting, 0x200|layer
    /// cutting, 0x300|layer in the track).
    phase: Py<PyArray1<u16>>,
    /// uint8 (n,): boundaries punctured in that tick.
    punctures: Py<PyArray1<u8>>,
    /// uint8 (n,): the step's `InsertionFlags` bits (`FAST_MOTION` 0x01, `OUT_OF_DOMAIN`
    /// 0x02, `NOT_FINITE` 0x04: a glitch, not integrated, the wrench held;
    /// `WRENCH_LIMITED` 0x08: the force or moment scaled down to its bound).
    flags: Py<PyArray1<u8>>,
    /// float32 (n,): the filtered axial velocity, mm/s.
    velocity_mm_per_s: Py<PyArray1<f32>>,
}

/// A needle's path through a tissue stack, stepped one pose per tick.
#[pyclass(module = "needle_haptics._native")]
pub struct Insertion {
    model: Model,
    stack: String,
}

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

#[pymethods]
impl Insertion {
    /// A path through the stack `stack`: the name of a compiled-in stack (see `stacks()`)
    /// or the path of a tissue file (`.toml`, loaded now and checked with the build's
    /// messages, `FILE:LINE`), the needle above the surface; `period_s` is the tick period,
    /// `velocity_time_constant_s` the velocity filter's.
    #[new]
    #[pyo3(signature = (stack, period_s = InsertionConfig::DEFAULT_1KHZ.period_s, velocity_time_constant_s = InsertionConfig::DEFAULT_1KHZ.velocity_time_constant_s))]
    fn new(stack: &str, period_s: f32, velocity_time_constant_s: f32) -> PyResult<Self> {
        let owned = OwnedStack::resolve("stack", stack).map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
        let config = InsertionConfig { period_s, velocity_time_constant_s, ..InsertionConfig::DEFAULT_1KHZ };
        let model = Model::new(&owned.as_stack(), config).map_err(value_error)?;
        Ok(Self { model, stack: owned.name })
    }

    /// The stack's name (a tissue file's `name`).
    #[getter]
    fn stack(&self) -> &str {
        &self.stack
    }

    /// Replaces the layers' stiffness scales (one per layer, each finite and > 0).
    fn set_scales(&mut self, scales: Vec<f32>) -> PyResult<()> {
        self.model.set_scales(&scales).map_err(value_error)
    }

    /// Forgets the path: the needle is above the surface again.
    fn reset(&mut self) {
        self.model.reset();
    }

    /// Steps every row of `poses` (float32 (n, 5)) in order, one tick each; the state
    /// carries over to the next call. A row that is not finite raises `PoseError` before
    /// any tick is taken.
    fn run<'py>(&mut self, py: Python<'py>, poses: &Bound<'py, PyAny>) -> PyResult<Trajectory> {
        let input = borrow(poses, "poses")?;
        let view = input.as_array();
        if let Some(row) = view.rows().into_iter().position(|r| r.iter().any(|v| !v.is_finite())) {
            return Err(not_finite(py, &view, row, "poses"));
        }
        let n = view.nrows();
        let wrench = PyArray2::<f32>::zeros(py, [n, 6], false);
        let status = PyArray1::<u8>::zeros(py, [n], false);
        let phase = PyArray1::<u16>::zeros(py, [n], false);
        let punctures = PyArray1::<u8>::zeros(py, [n], false);
        let flags = PyArray1::<u8>::zeros(py, [n], false);
        let velocity = PyArray1::<f32>::zeros(py, [n], false);
        {
            let (mut w, mut s, mut p, mut c, mut f, mut v) =
                (wrench.readwrite(), status.readwrite(), phase.readwrite(), punctures.readwrite(), flags.readwrite(), velocity.readwrite());
            let (mut w, mut s, mut p, mut c, mut f, mut v) =
                (w.as_array_mut(), s.as_array_mut(), p.as_array_mut(), c.as_array_mut(), f.as_array_mut(), v.as_array_mut());
            let model = &mut self.model;
            py.detach(|| {
                for (row, mut w_row) in w.rows_mut().into_iter().enumerate() {
                    let e = model.step(&pose_at(&view, row));
                    for (o, x) in w_row.iter_mut().zip(e.wrench.to_array()) {
                        *o = x;
                    }
                    let (Some(s), Some(p), Some(c), Some(f), Some(v)) =
                        (s.get_mut(row), p.get_mut(row), c.get_mut(row), f.get_mut(row), v.get_mut(row))
                    else {
                        break;
                    };
                    *f = e.flags.bits();
                    *s = e.status.bits();
                    *p = e.phase.code();
                    *c = e.punctures;
                    *v = e.velocity_mm_per_s;
                    debug_assert!(e.status.bits() & Status::ERROR.bits() == 0);
                }
            });
        }
        Ok(Trajectory {
            wrench: wrench.unbind(),
            status: status.unbind(),
            phase: phase.unbind(),
            punctures: punctures.unbind(),
            flags: flags.unbind(),
            velocity_mm_per_s: velocity.unbind(),
        })
    }

    fn __repr__(&self) -> String {
        format!("Insertion(stack={:?})", self.stack)
    }
}

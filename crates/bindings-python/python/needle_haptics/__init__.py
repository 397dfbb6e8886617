"""needle-haptics from Python: the library's own f32 evaluators and insertion model
(Rust, through PyO3) over NumPy arrays, the set's FE runs as arrays, and a NumPy-only
reference of the model.

    import numpy as np, needle_haptics as nh
    poses = np.array([[2, 1, 3, 0, 5]], dtype=np.float32)  # x_mm z_mm theta_x_deg theta_z_deg depth_mm
    wrench, status = nh.wrench(poses)                        # (n, 6) float32, (n,) uint8

Frames and units: docs/architecture.md, section 3.
"""
from ._native import (
    COMPONENTS,
    COUPLED,
    FITTED,
    POSE_COLUMNS,
    SET,
    SET_DIR,
    Calibration,
    CurveError,
    Insertion,
    PoseError,
    Trajectory,
    calibrate,
    sample_stack,
    stack_names,
    wrench,
    wrench_and_stiffness,
)
from .fe import FeRun, fe_runs

__all__ = [
    "COMPONENTS",
    "COUPLED",
    "FITTED",
    "POSE_COLUMNS",
    "SET",
    "SET_DIR",
    "Calibration",
    "CurveError",
    "FeRun",
    "Insertion",
    "PoseError",
    "Trajectory",
    "calibrate",
    "fe_runs",
    "sample_stack",
    "stack_names",
    "wrench",
    "wrench_and_stiffness",
]

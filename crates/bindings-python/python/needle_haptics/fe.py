"""The set's FE runs as arrays: `fe/manifest.toml` (each run's pose and how it was made)
and `fe/<pose>.csv` (the wrench at every depth); formats in coeffs/README.md."""
from __future__ import annotations

import os
import sys
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np
import numpy.typing as npt

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.9/3.10
    import tomli as tomllib

from ._native import COMPONENTS, SET_DIR


@dataclass(frozen=True)
class FeRun:
    """One FE run: its name, role, pose (without depth) and the wrench at every depth."""

    name: str
    role: str
    x_mm: float
    z_mm: float
    theta_x_deg: float
    theta_z_deg: float
    depth_mm: npt.NDArray[np.float64]
    """(m,) the depths solved, mm."""
    wrench: npt.NDArray[np.float64]
    """(m, 6) the reaction wrench at each depth, `COMPONENTS` order (N, N*mm about the hub)."""
    manifest: dict[str, Any] = field(repr=False)
    """The run's whole `[pose.<name>]` table (engine, version, mesh, settings, ...)."""

    def poses(self) -> npt.NDArray[np.float32]:
        """The run's poses as the library takes them: float32 (m, 5)."""
        p = np.empty((len(self.depth_mm), 5), dtype=np.float32)
        p[:, :4] = (self.x_mm, self.z_mm, self.theta_x_deg, self.theta_z_deg)
        p[:, 4] = self.depth_mm
        return p


def fe_runs(set_dir: Optional[str] = None) -> dict[str, FeRun]:
    """Every run of `set_dir/fe/manifest.toml` (default: the set compiled in), by name."""
    folder = os.path.join(set_dir or SET_DIR, "fe")
    with open(os.path.join(folder, "manifest.toml"), "rb") as f:
        manifest = tomllib.load(f)
    runs = {}
    for name, entry in manifest.get("pose", {}).items():
        path = os.path.join(folder, f"{name}.csv")
        with open(path, encoding="utf-8") as f:
            header = f.readline().strip().split(",")
        want = ["depth_mm", *COMPONENTS]
        if header != want:
            raise ValueError(f"{path}: columns {header}, expected {want}")
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2, dtype=np.float64)
        runs[name] = FeRun(
            name=name,
            role=entry["role"],
            x_mm=entry["x_mm"],
            z_mm=entry["z_mm"],
            theta_x_deg=entry["theta_x_deg"],
            theta_z_deg=entry["theta_z_deg"],
            depth_mm=data[:, 0],
            wrench=data[:, 1:],
            manifest=entry,
        )
    return runs

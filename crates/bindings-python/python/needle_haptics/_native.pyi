"""Type hints of the Rust extension module (src/*.rs)."""
import os
from typing import Any, Final, Optional, Union

import numpy as np
import numpy.typing as npt

SET: Final[str]
SET_DIR: Final[str]
COUPLED: Final[bool]
FITTED: Final[bool]
POSE_COLUMNS: Final[list[str]]
COMPONENTS: Final[list[str]]

class PoseError(ValueError):
    """A pose array the library cannot take; `row` and `column` say where (None: the whole array)."""

    row: Optional[int]
    column: Optional[int]

def wrench(
    poses: npt.NDArray[np.float32], /
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8]]:
    """(wrench (n, 6) float32 in N and N*mm about the hub, status (n,) uint8) at every pose row (n, 5)."""

def wrench_and_stiffness(
    poses: npt.NDArray[np.float32], /
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32], npt.NDArray[np.uint8]]:
    """(wrench (n, 6), stiffness (n, 3, 6): d/d depth_mm, d/d x_mm, d/d z_mm in N/mm and N*mm/mm, status (n,))."""

def stack_names() -> list[str]:
    """The tissue stacks compiled into this build."""

class Trajectory:
    """One row per tick of `Insertion.run`."""

    @property
    def wrench(self) -> npt.NDArray[np.float32]: ...
    @property
    def status(self) -> npt.NDArray[np.uint8]: ...
    @property
    def phase(self) -> npt.NDArray[np.uint16]: ...
    @property
    def punctures(self) -> npt.NDArray[np.uint8]: ...
    @property
    def flags(self) -> npt.NDArray[np.uint8]:
        """(n,) the step's flags: 0x01 FAST_MOTION, 0x02 OUT_OF_DOMAIN, 0x04 NOT_FINITE (a glitch: not integrated, the wrench held), 0x08 WRENCH_LIMITED."""
    @property
    def velocity_mm_per_s(self) -> npt.NDArray[np.float32]: ...

class Insertion:
    """A needle's path through a compiled-in tissue stack, one pose per tick."""

    def __init__(self, stack: str, period_s: float = 0.001, velocity_time_constant_s: float = 0.005) -> None: ...
    @property
    def stack(self) -> str: ...
    def set_scales(self, scales: list[float]) -> None: ...
    def reset(self) -> None: ...
    def run(self, poses: npt.NDArray[np.float32]) -> Trajectory: ...

class CurveError(ValueError):
    """A measured curve `calibrate` cannot take. `row`: 0-based data row; `column`:
    "position_mm" or "force_n"; `line`: 1-based line of the CSV file (None when not known
    or not one place)."""

    row: Optional[int]
    column: Optional[str]
    line: Optional[int]

class Calibration:
    """The result of `calibrate`: the tissue stack, the model along the curve, the residuals."""

    @property
    def toml(self) -> str:
        """The tissue file's text as `needle calibrate` writes it (without its # header)."""
    @property
    def stack(self) -> dict[str, Any]:
        """The same stack: format, name, description, needle_diameter_mm, layer (list of dicts, the file's keys)."""
    @property
    def onset_mm(self) -> float:
        """Needle position of contact (depth 0), mm."""
    @property
    def similarity(self) -> float:
        """Measured needle diameter over the FE needle's."""
    @property
    def position_mm(self) -> npt.NDArray[np.float64]:
        """(m,) the measured needle positions, mm."""
    @property
    def force_n(self) -> npt.NDArray[np.float64]:
        """(m,) the measured axial force, N."""
    @property
    def model_force_n(self) -> npt.NDArray[np.float64]:
        """(m,) the calibrated stack's force at each measured position (nearest 1 kHz tick), N."""
    @property
    def residual_n(self) -> npt.NDArray[np.float64]:
        """(m,) force_n - model_force_n, N."""
    @property
    def replay(self) -> npt.NDArray[np.float64]:
        """(t, 2) the model per tick: needle position mm, axial force N."""
    @property
    def measured_punctures(self) -> npt.NDArray[np.float64]:
        """(k, 2) the punctures found in the curve: position mm, peak force N."""
    @property
    def model_punctures(self) -> npt.NDArray[np.float64]:
        """(k', 2) the model's punctures: position mm, force N just before."""
    @property
    def checks(self) -> list[dict[str, Any]]:
        """Model against curve: what, measured, model, error, goal, unit, met."""
    @property
    def all_met(self) -> bool:
        """Whether every check is met (`needle calibrate` exits 1 otherwise)."""

def calibrate(
    curve: Union[str, "os.PathLike[str]", tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]],
    /,
    *,
    name: str,
    needle_diameter_mm: float,
    speed_mm_per_s: float,
    drop_fraction: float = ...,
    label: Optional[str] = None,
) -> Calibration:
    """`needle calibrate` on a CSV file (columns position_mm, force_n) or on (position_mm,
    force_n) float64 arrays, against the set compiled in. `label` names the curve in the
    stack's description and source (default: the path, or "arrays"). Raises CurveError
    (row, column, line) for a bad curve, ValueError when it cannot calibrate."""

def sample_stack(
    stack: Union[str, "os.PathLike[str]"],
    /,
    *,
    seed: int,
    name: Optional[str] = None,
    spread: Optional[Union[str, "os.PathLike[str]"]] = None,
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> str:
    """`needle stack sample`: a tissue drawn within the spread `stack` was fitted with
    (`spread`, default `<stem>.spread.csv` beside it), the same draw as the command (the
    same files and seed, the same text). Returns the tissue file's text, named `name`
    (default: `out`'s stem, else `<stack's stem>_seed<seed>`); with `out` also writes it
    (atomically). Raises ValueError naming the file and line of a refused input."""

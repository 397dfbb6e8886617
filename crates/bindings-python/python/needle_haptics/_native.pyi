"""Type hints of the Rust extension module (src/*.rs)."""
from typing import Final, Optional

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
    def velocity_mm_per_s(self) -> npt.NDArray[np.float32]: ...

class Insertion:
    """A needle's path through a compiled-in tissue stack, one pose per tick."""

    def __init__(self, stack: str, period_s: float = 0.001, velocity_time_constant_s: float = 0.005) -> None: ...
    @property
    def stack(self) -> str: ...
    def set_scales(self, scales: list[float]) -> None: ...
    def reset(self) -> None: ...
    def run(self, poses: npt.NDArray[np.float32]) -> Trajectory: ...

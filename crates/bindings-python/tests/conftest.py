"""What the tests share: the golden files of the set compiled in (written by the fitter,
`needle fit`), read as float32 bits."""
import os

import numpy as np
import pytest

import needle_haptics as nh


def read_hex_csv(name: str) -> tuple[list[str], np.ndarray]:
    """(header, uint32 array) of a golden file whose every field is 0x-hex."""
    path = os.path.join(nh.SET_DIR, name)
    with open(path, encoding="utf-8") as f:
        header = f.readline().strip().split(",")
        rows = [[int(v, 16) for v in line.strip().split(",")] for line in f if line.strip()]
    return header, np.array(rows, dtype=np.uint32)


class Golden:
    """One golden file: poses (float32 (n, 5)), status (uint8), outputs (uint32 bits)."""

    def __init__(self, name: str):
        self.header, table = read_hex_csv(name)
        assert self.header[:6] == [*nh.POSE_COLUMNS, "status"], self.header
        self.poses = np.ascontiguousarray(table[:, :5]).view(np.float32)
        self.status = table[:, 5].astype(np.uint8)
        self.bits = np.ascontiguousarray(table[:, 6:])
        self.finite = np.isfinite(self.poses).all(axis=1)


@pytest.fixture(scope="session")
def golden_f32() -> Golden:
    g = Golden("golden-f32.csv")
    assert g.header[6:] == nh.COMPONENTS
    return g


@pytest.fixture(scope="session")
def golden_stiffness() -> Golden:
    return Golden("golden-stiffness-f32.csv")


def same_bits(want: np.ndarray, got: np.ndarray) -> np.ndarray:
    """Per element: the same float32 bits, or both NaN."""
    got_bits = np.ascontiguousarray(got, dtype=np.float32).view(np.uint32)
    want_f = want.view(np.float32)
    return (got_bits == want) | (np.isnan(want_f) & np.isnan(got))

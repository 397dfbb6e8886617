"""A NumPy-only evaluation of a set's model, written from the contract in
coeffs/README.md ("Evaluation algorithm", "The coupled form") and `model.toml`, not from
the library: float32 arrays, every operation rounded on its own, in the contract's order.

It is the side-by-side reference of the timing comparison (examples/timing.py) and a
second implementation the tests hold against the golden vectors.
"""
from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from ._native import COMPONENTS, SET_DIR

F32 = np.float32
SWEEPS = ("x", "z", "theta_x", "theta_z")
HALF_RANGES = (12.0, 12.0, 15.0, 15.0)  # V_k, mm or degrees
DEPTH_MAX_MM = 6.0
SAT_BITS = (0x01, 0x02, 0x04, 0x08, 0x10)
FE_UNSOLVED = 0x20
ERROR = 0x80
CROSS_SCALES = (1.0 / 12.0, 1.0 / 12.0, 1.0 / 15.0, 1.0 / 15.0)  # their nearest float32


def _f32(hex_words: list[str]) -> npt.NDArray[np.float32]:
    return np.array([int(h, 16) for h in hex_words], dtype=np.uint32).view(np.float32)


def _horner(coeffs: list[np.float32], w: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    """(((p4*w + p3)*w + p2)*w + p1)*w + p0, each operation rounded to float32."""
    acc = np.full(w.shape, coeffs[-1], dtype=np.float32)
    for p in reversed(coeffs[:-1]):
        acc = acc * w
        acc = acc + p
    return acc


@dataclass(frozen=True)
class NumpyModel:
    """The f32 coefficients of one `model.toml`."""

    baseline: list[list[np.float32]]  # [c][i]
    deviation: list[list[tuple[bool, list[list[np.float32]]]]]  # [k][c] = (odd, rows[i][j])
    cross: list[tuple[int, list[int], list[np.float32]]]  # (c, exponents, coeffs)
    # the unsolved region (unsolved.toml beside model.toml): per ball, the centre C / 2^15,
    # the float32 nearest R^2 / 2^30 and the depth threshold Dq / 2^16 mm
    unsolved: list[tuple[list[np.float32], np.float32, np.float32]]

    @staticmethod
    def load(set_dir: Optional[str] = None) -> "NumpyModel":
        path = os.path.join(set_dir or SET_DIR, "model.toml")
        with open(path, "rb") as f:
            m = tomllib.load(f)
        index = {name: c for c, name in enumerate(COMPONENTS)}
        baseline: list[list[np.float32]] = [[] for _ in COMPONENTS]
        for b in m["baseline"]:
            baseline[index[b["component"]]] = list(_f32(b["coeffs_f32"]))
        deviation: list[list[tuple[bool, list[list[np.float32]]]]] = [[(False, [])] * len(COMPONENTS) for _ in SWEEPS]
        for d in m["matrix"]:
            rows = [list(_f32(r)) for r in d["rows_f32"]]
            deviation[SWEEPS.index(d["sweep"])][index[d["component"]]] = (bool(d["odd"]), rows)
        cross = [(index[t["component"]], list(t["exponents"]), list(_f32(t["coeffs_f32"]))) for t in m.get("cross", [])]
        unsolved: list[tuple[list[np.float32], np.float32, np.float32]] = []
        region_path = os.path.join(set_dir or SET_DIR, "unsolved.toml")
        if os.path.exists(region_path):
            with open(region_path, "rb") as f:
                region = tomllib.load(f)
            for failed in region.get("failed", []):
                r = int(failed["radius_q15"])
                for c in failed["centres_q15"]:
                    unsolved.append(
                        ([F32(v / 32768.0) for v in c], F32((r * r) / 2.0**30), F32(int(failed["depth_q16"]) / 65536.0))
                    )
        return NumpyModel(baseline, deviation, cross, unsolved)

    def wrench(self, poses: npt.NDArray[np.float32]) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8]]:
        """(wrench (n, 6) float32, status (n,) uint8) at every row of `poses` (n, 5) float32;
        a row with a NaN or infinite value gives the zero wrench and status 0x80."""
        with np.errstate(invalid="ignore", over="ignore"):
            return self._wrench(np.asarray(poses, dtype=np.float32))

    def _wrench(self, poses: npt.NDArray[np.float32]) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint8]]:
        n = poses.shape[0]
        status = np.zeros(n, dtype=np.uint8)
        limits = [(-h, h) for h in HALF_RANGES] + [(0.0, DEPTH_MAX_MM)]
        clamped = []
        for col, ((lo, hi), bit) in enumerate(zip(limits, SAT_BITS)):
            v = poses[:, col]
            c = np.minimum(np.maximum(v, F32(lo)), F32(hi))
            status |= np.where(c != v, np.uint8(bit), np.uint8(0))
            clamped.append(c)
        bad = ~np.isfinite(poses).all(axis=1)
        u = clamped[4] * F32(1.0 / 3.0) - F32(1.0)
        ts, neg = [], []
        for k, half in enumerate(HALF_RANGES):
            v = clamped[k]
            ts.append(np.abs(v) * F32(2.0 / half) - F32(1.0))
            neg.append(v < 0)
        out = np.empty((n, len(COMPONENTS)), dtype=np.float32)
        for c in range(len(COMPONENTS)):
            w = _horner(self.baseline[c], u)
            for k in range(len(SWEEPS)):
                odd, rows = self.deviation[k][c]
                r = [_horner(row, ts[k]) for row in rows]
                acc = r[4]
                for ri in reversed(r[:4]):
                    acc = acc * u + ri
                w = np.where(neg[k] & odd, w - acc, w + acc)
            out[:, c] = w
        ns = [clamped[k] * F32(CROSS_SCALES[k]) for k in range(4)]
        if self.cross:
            for c, exponents, coeffs in self.cross:
                factors = [ns[k] for k, e in enumerate(exponents) for _ in range(e)]
                m = factors[0]
                for f in factors[1:]:
                    m = m * f
                out[:, c] = out[:, c] + m * _horner(coeffs, u)
        # the unsolved region (FE_UNSOLVED): on the clamped pose; the wrench is not changed
        for centre, r2, depth in self.unsolved:
            q = [ns[k] - centre[k] for k in range(4)]
            s = ((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]) + q[3] * q[3]
            status |= np.where((clamped[4] > depth) & (s < r2), np.uint8(FE_UNSOLVED), np.uint8(0))
        out[bad] = 0.0
        status[bad] = ERROR
        return out, status

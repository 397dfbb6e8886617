"""The binding gives the library's bits: every golden vector of the fitter (`needle
fit`'s own f32 evaluation), wrench and stiffness, status included."""
import numpy as np
import pytest

import needle_haptics as nh
from conftest import same_bits


def test_wrench_is_bit_exact_on_every_finite_golden_row(golden_f32):
    g = golden_f32
    assert g.finite.sum() > 4000, "the golden file covers the domain"
    wrench, status = nh.wrench(g.poses[g.finite])
    assert wrench.dtype == np.float32 and wrench.shape == (g.finite.sum(), 6)
    ok = same_bits(g.bits[g.finite], wrench)
    bad = np.flatnonzero(~ok.all(axis=1))
    assert bad.size == 0, f"{bad.size} rows differ, first golden row {np.flatnonzero(g.finite)[bad[0]] + 2} (file line)"
    np.testing.assert_array_equal(status, g.status[g.finite])


def test_every_non_finite_golden_row_raises_naming_its_row_and_column(golden_f32):
    g = golden_f32
    rows = np.flatnonzero(~g.finite)
    assert rows.size > 0 and (g.status[rows] == 0x80).all(), "the golden file's error rows have status ERROR"
    for r in rows:
        with pytest.raises(nh.PoseError) as e:
            nh.wrench(g.poses[r : r + 1])
        column = int(np.flatnonzero(~np.isfinite(g.poses[r]))[0])
        assert (e.value.row, e.value.column) == (0, column)
        assert f"poses[0, {column}] ({nh.POSE_COLUMNS[column]})" in str(e.value)


def test_stiffness_is_bit_exact_on_every_finite_golden_row(golden_stiffness):
    g = golden_stiffness
    wrench, stiffness, status = nh.wrench_and_stiffness(g.poses[g.finite])
    assert stiffness.shape == (g.finite.sum(), 3, 6)
    ok = same_bits(g.bits[g.finite], stiffness.reshape(-1, 18))
    bad = np.flatnonzero(~ok.all(axis=1))
    assert bad.size == 0, f"{bad.size} rows differ, first at finite row {bad[0]}"
    np.testing.assert_array_equal(status, g.status[g.finite])
    plain, _ = nh.wrench(g.poses[g.finite])
    np.testing.assert_array_equal(wrench.view(np.uint32), plain.view(np.uint32))


def test_the_numpy_reference_is_bit_exact_too(golden_f32):
    """The NumPy-only evaluation (the timing's reference) is the same model, bit for bit,
    NaN rows included (zero wrench, status 0x80)."""
    from needle_haptics.numpy_model import NumpyModel

    g = golden_f32
    wrench, status = NumpyModel.load().wrench(g.poses)
    ok = same_bits(g.bits, wrench)
    assert ok.all(), f"first differing file line {np.flatnonzero(~ok.all(axis=1))[0] + 2}"
    np.testing.assert_array_equal(status, g.status)


def test_a_strided_view_is_read_in_place_with_the_same_bits(golden_f32):
    g = golden_f32
    poses = g.poses[g.finite]
    wide = np.zeros((poses.shape[0] * 2, 8), dtype=np.float32)
    wide[::2, 1:6] = poses
    view = wide[::2, 1:6]
    assert not view.flags.c_contiguous
    a, _ = nh.wrench(view)
    b, _ = nh.wrench(poses)
    np.testing.assert_array_equal(a.view(np.uint32), b.view(np.uint32))


def test_many_rows_split_over_threads_keep_row_order(golden_f32):
    """Above the per-thread threshold the rows are split; every row lands in its place."""
    g = golden_f32
    poses = np.tile(g.poses[g.finite], (40, 1))
    assert poses.shape[0] > 2 * 32_768
    wrench, status = nh.wrench(poses)
    want = np.tile(g.bits[g.finite], (40, 1))
    assert same_bits(want, wrench).all()

"""A bad pose array raises `PoseError` (a ValueError) that says which row and column."""
import numpy as np
import pytest

import needle_haptics as nh


def good(n: int = 4) -> np.ndarray:
    p = np.zeros((n, 5), dtype=np.float32)
    p[:, 4] = 3.0
    return p


@pytest.mark.parametrize("f", [nh.wrench, nh.wrench_and_stiffness, lambda p: nh.Insertion("liver").run(p)])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_value_names_row_and_column(f, bad):
    p = good(7)
    p[5, 3] = bad
    p[6, 0] = np.nan  # a later row: the first one is named
    with pytest.raises(nh.PoseError, match=r"poses\[5, 3\] \(theta_z_deg\) is (NaN|inf|-inf)") as e:
        f(p)
    assert (e.value.row, e.value.column) == (5, 3)
    assert isinstance(e.value, ValueError)


@pytest.mark.parametrize("f", [nh.wrench, nh.wrench_and_stiffness])
def test_wrong_column_count_names_the_column(f):
    with pytest.raises(nh.PoseError, match=r"has 4 columns, the pose has 5 .*column 4 is missing") as e:
        f(np.zeros((3, 4), dtype=np.float32))
    assert (e.value.row, e.value.column) == (None, 4)
    with pytest.raises(nh.PoseError, match=r"has 6 columns.*column 5 is one too many"):
        f(np.zeros((3, 6), dtype=np.float32))


def test_wrong_dimensions_and_non_arrays():
    with pytest.raises(nh.PoseError, match=r"2 dimensions \(n, 5\), got shape \[5\]"):
        nh.wrench(np.zeros(5, dtype=np.float32))
    with pytest.raises(nh.PoseError, match=r"must be a numpy.ndarray .* got a list"):
        nh.wrench([[0, 0, 0, 0, 3]])


def test_float64_names_the_first_value_float32_cannot_hold():
    p = good(3).astype(np.float64)
    p[2, 4] = 0.1
    with pytest.raises(nh.PoseError, match=r"dtype float64.*poses\[2, 4\] \(depth_mm\) = 0.1 is not a float32 value") as e:
        nh.wrench(p)
    assert (e.value.row, e.value.column) == (2, 4)
    with pytest.raises(nh.PoseError, match=r"every value is a float32 value"):
        nh.wrench(good(3).astype(np.float64))
    with pytest.raises(nh.PoseError, match=r"dtype int64, the library takes float32"):
        nh.wrench(np.zeros((2, 5), dtype=np.int64))


def test_an_empty_array_gives_empty_outputs():
    w, s = nh.wrench(np.zeros((0, 5), dtype=np.float32))
    assert w.shape == (0, 6) and s.shape == (0,)


def test_out_of_domain_saturates_without_raising():
    p = good(1)
    p[0, 0] = 20.0
    _, s = nh.wrench(p)
    assert s[0] == 0x01

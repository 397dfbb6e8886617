"""The set's FE runs as arrays: every run of fe/manifest.toml, its pose, and its CSV's
numbers (read here with the csv module, apart from the package's numpy reader)."""
import csv
import os
import sys

import numpy as np

import needle_haptics as nh

if sys.version_info >= (3, 11):
    import tomllib


def test_every_manifest_run_is_there_with_its_pose_and_numbers():
    runs = nh.fe_runs()
    with open(os.path.join(nh.SET_DIR, "fe", "manifest.toml"), "rb") as f:
        manifest = tomllib.load(f)["pose"]
    assert set(runs) == set(manifest) and len(runs) > 20
    for name, run in runs.items():
        assert run.role == manifest[name]["role"]
        assert (run.x_mm, run.z_mm, run.theta_x_deg, run.theta_z_deg) == tuple(manifest[name][k] for k in nh.POSE_COLUMNS[:4])
        with open(os.path.join(nh.SET_DIR, "fe", f"{name}.csv"), encoding="utf-8") as f:
            rows = list(csv.reader(f))
        assert rows[0] == ["depth_mm", *nh.COMPONENTS]
        table = np.array([[float(v) for v in r] for r in rows[1:]])
        np.testing.assert_array_equal(run.depth_mm, table[:, 0])
        np.testing.assert_array_equal(run.wrench, table[:, 1:])
        poses = run.poses()
        assert poses.dtype == np.float32 and poses.shape == (len(run.depth_mm), 5)


def test_centre_run_against_the_model():
    """The model at the centre run's poses: close to the FE run it was fitted on (the
    set's README gives the fit's error; here within 5 % of peak Fy)."""
    centre = nh.fe_runs()["centre"]
    inside = centre.depth_mm <= 6.0
    wrench, status = nh.wrench(centre.poses()[inside])
    fy = centre.wrench[inside, 1]
    assert np.abs(wrench[:, 1] - fy).max() <= 0.05 * np.abs(fy).max()

"""`calibrate` from Python gives the stack `needle calibrate` (the library's own command
line, run here) writes for the shipped measured curve (Okamura, Simone and O'Leary 2004,
bovine liver), which is also the shipped `tissue/liver.toml`; arrays in give the same
stack as the CSV; a bad curve names its row and column."""
import csv
import os
import re
import subprocess
import tomllib

import numpy as np
import pytest

import needle_haptics as nh

ROOT = os.path.dirname(os.path.dirname(nh.SET_DIR))
SET = os.path.relpath(nh.SET_DIR, ROOT)
CURVE = os.path.join(SET, "measured", "okamura2004-bovine-liver", "position_force.csv")
SHIPPED = os.path.join(nh.SET_DIR, "tissue", "liver.toml")


def body(text: str) -> str:
    """A tissue file's text without its leading # header (the command line's own note)."""
    lines = text.splitlines(keepends=True)
    while lines and lines[0].startswith("#"):
        lines.pop(0)
    return "".join(lines)


def measurement() -> dict:
    """The shipped stack's measurement as its header states it (needle mm at speed mm/s)."""
    with open(SHIPPED, encoding="utf-8") as f:
        header = "".join(l for l in f if l.startswith("#"))
    m = re.search(r"needle ([0-9.]+) mm at ([0-9.]+) mm/s", header)
    assert m, f"{SHIPPED}: no 'needle D mm at S mm/s' in its header"
    return {"name": "liver", "needle_diameter_mm": float(m.group(1)), "speed_mm_per_s": float(m.group(2))}


@pytest.fixture(scope="module")
def cli(tmp_path_factory) -> tuple[str, str]:
    """(the tissue file, standard output) of `needle calibrate` on the shipped curve."""
    exe = os.environ.get("NEEDLE_BIN")
    assert exe and os.path.isfile(exe), "NEEDLE_BIN must name the needle binary (.ci/test-python builds it)"
    out = tmp_path_factory.mktemp("calibrate")
    m = measurement()
    args = [exe, "calibrate", "--set", SET, "--curve", CURVE, "--name", m["name"], "--needle-diameter-mm", repr(m["needle_diameter_mm"]),
            "--speed-mm-per-s", repr(m["speed_mm_per_s"]), "--out", str(out / "liver.toml"), "--figure", str(out / "liver.svg")]
    run = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    with open(out / "liver.toml", encoding="utf-8") as f:
        return f.read(), run.stdout


@pytest.fixture(scope="module")
def from_csv() -> nh.Calibration:
    cwd = os.getcwd()
    os.chdir(ROOT)  # the curve named as the command line names it (it goes into the file)
    try:
        return nh.calibrate(CURVE, **measurement())
    finally:
        os.chdir(cwd)


def test_the_stack_is_the_one_needle_calibrate_writes(cli, from_csv):
    text, _ = cli
    assert from_csv.toml == body(text)
    assert from_csv.stack == tomllib.loads(text)
    with open(SHIPPED, encoding="utf-8") as f:
        assert body(f.read()) == from_csv.toml, "tissue/liver.toml is not what needle calibrate writes today"


def test_the_checks_are_the_ones_needle_calibrate_prints(cli, from_csv):
    _, stdout = cli
    printed = re.findall(r"^(.*?)\s+measured\s+(\S+)\s+model\s+(\S+)\s+error .*\s(ok|MISSED)$", stdout, re.M)
    assert len(printed) == len(from_csv.checks) >= 5, stdout
    for (what, measured, model, met), k in zip(printed, from_csv.checks):
        assert (what, measured, model, met) == (k["what"], f"{k['measured']:.4f}", f"{k['model']:.4f}", "ok" if k["met"] else "MISSED")
    assert from_csv.all_met and "every calibration goal met" in stdout


def test_the_residuals_are_the_measured_curve_minus_the_model_at_its_nearest_tick(from_csv):
    c = from_csv
    with open(os.path.join(ROOT, CURVE), encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    np.testing.assert_array_equal(c.position_mm, [float(r["position_mm"]) for r in rows])
    np.testing.assert_array_equal(c.force_n, [float(r["force_n"]) for r in rows])
    ticks = c.replay
    assert ticks.shape[1] == 2 and ticks.shape[0] > 1000 and np.all(np.diff(ticks[:, 0]) > 0)
    nearest = np.abs(ticks[:, 0][None, :] - c.position_mm[:, None]).argmin(axis=1)
    np.testing.assert_array_equal(c.model_force_n, ticks[nearest, 1])
    np.testing.assert_array_equal(c.residual_n, c.force_n - c.model_force_n)
    puncture_checks = [k for k in c.checks if re.fullmatch(r"puncture \d+ position", k["what"])]
    assert c.measured_punctures.shape == (len(puncture_checks), 2) and c.model_punctures.shape[1] == 2
    np.testing.assert_array_equal(c.measured_punctures[:, 0], [k["measured"] for k in puncture_checks])


def test_arrays_give_the_same_stack_as_the_file(from_csv):
    with open(os.path.join(ROOT, CURVE), encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    position = np.array([float(r["position_mm"]) for r in rows])
    force = np.array([float(r["force_n"]) for r in rows])
    c = nh.calibrate((position, force), label=CURVE, **measurement())
    assert c.toml == from_csv.toml
    np.testing.assert_array_equal(c.residual_n, from_csv.residual_n)
    unlabelled = nh.calibrate((position, force), **measurement())
    assert unlabelled.stack["description"] == "calibrated by needle calibrate on arrays"


def curve_arrays() -> tuple[np.ndarray, np.ndarray]:
    data = np.loadtxt(os.path.join(ROOT, CURVE), delimiter=",", skiprows=1)
    return np.ascontiguousarray(data[:, 0]), np.ascontiguousarray(data[:, 1])


def test_a_value_that_is_not_finite_names_its_row_and_column():
    position, force = curve_arrays()
    force[7] = np.nan
    with pytest.raises(nh.CurveError, match=r"force_n\[7\]: is NaN: every value must be finite") as e:
        nh.calibrate((position, force), **measurement())
    assert (e.value.row, e.value.column, e.value.line) == (7, "force_n", None)
    position[3] = np.inf
    with pytest.raises(nh.CurveError, match=r"position_mm\[3\]: is inf") as e:
        nh.calibrate((position, force), **measurement())
    assert (e.value.row, e.value.column) == (3, "position_mm")


def test_a_bad_csv_value_names_its_line_row_and_column(tmp_path):
    with open(os.path.join(ROOT, CURVE), encoding="utf-8") as f:
        lines = f.read().splitlines(keepends=True)
    lines[5] = lines[5].replace(",", ",x", 1)  # line 6 of the file, data row 4: force_n
    bad = tmp_path / "bad.csv"
    bad.write_text("".join(lines), encoding="utf-8")
    with pytest.raises(nh.CurveError, match=r"bad.csv:6: column force_n: \"x.*\" is not a number") as e:
        nh.calibrate(bad, **measurement())
    assert (e.value.line, e.value.row, e.value.column) == (6, 4, "force_n")
    nocol = tmp_path / "nocol.csv"
    nocol.write_text("".join(lines).replace("force_n", "load_n", 1), encoding="utf-8")
    with pytest.raises(nh.CurveError, match=r'nocol.csv:1: no column "force_n"') as e:
        nh.calibrate(nocol, **measurement())
    assert (e.value.line, e.value.row, e.value.column) == (1, None, "force_n")


def test_bad_arrays_say_how_to_convert():
    position, force = curve_arrays()
    with pytest.raises(nh.CurveError, match=r"force_n has dtype float32, not float64: np.asarray") as e:
        nh.calibrate((position, force.astype(np.float32)), **measurement())
    assert e.value.column == "force_n"
    with pytest.raises(nh.CurveError, match=r"position_mm is a list, not a numpy.ndarray"):
        nh.calibrate((list(position), force), **measurement())
    with pytest.raises(nh.CurveError, match=rf"{position.size} positions and {position.size - 1} forces") as e:
        nh.calibrate((position, force[:-1]), **measurement())
    assert (e.value.row, e.value.column) == (None, None)
    with pytest.raises(ValueError, match="curve is a tuple of 3"):
        nh.calibrate((position, force, force), **measurement())


def test_a_curve_without_a_puncture_cannot_calibrate():
    position, force = curve_arrays()
    rising = slice(0, int(np.argmax(np.where(position < 20.0, force, -np.inf))) + 1)
    with pytest.raises(ValueError, match="no puncture found") as e:
        nh.calibrate((position[rising], force[rising]), **measurement())
    assert not isinstance(e.value, nh.CurveError)
    with pytest.raises(ValueError, match=r"must be a number from 0\.01 to 1000 mm/s"):
        nh.calibrate((position, force), **{**measurement(), "speed_mm_per_s": 0.0})

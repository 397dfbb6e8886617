"""The insertion model from Python steps the same ticks, with the same bits, as the
library's own command line (`needle eval --poses --insertion`, the Rust library in the
`needle` binary): a scripted insertion that punctures, withdraws and re-enters."""
import csv
import os
import subprocess

import numpy as np
import pytest

import needle_haptics as nh


def trajectory() -> np.ndarray:
    """1 kHz: down to 30 mm in 6 s, back to 12 mm, in again to 35 mm, out above the surface."""
    depth = np.concatenate([np.linspace(-1, 30, 6000), np.linspace(30, 12, 2000), np.linspace(12, 35, 3000), np.linspace(35, -1, 4000)])
    p = np.zeros((depth.size, 5), dtype=np.float32)
    p[:, 0], p[:, 1], p[:, 2], p[:, 3] = 1.5, -0.5, 4.0, -2.0
    p[:, 4] = depth
    return p


def needle_cli(poses: np.ndarray, stack: str, tmp_path) -> list[dict[str, str]]:
    exe = os.environ.get("NEEDLE_BIN")
    assert exe and os.path.isfile(exe), "NEEDLE_BIN must name the needle binary (.ci/test-python builds it)"
    path = tmp_path / "poses.csv"
    with open(path, "w", encoding="utf-8") as f:
        f.write("time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n")
        for i, row in enumerate(poses):
            # repr of a float32 widened to float64: exact, so the CLI parses the same f32
            f.write(f"{i * 0.001!r}," + ",".join(repr(float(v)) for v in row) + "\n")
    out = subprocess.run([exe, "eval", "--set", nh.SET_DIR, "--poses", str(path), "--insertion", stack], check=True, capture_output=True, text=True)
    return list(csv.DictReader(out.stdout.splitlines()))


def phase_code(text: str) -> int:
    kinds = {"approach": 0, "deflecting": 0x100, "cutting": 0x200, "in-track": 0x300}
    kind, _, layer = text.partition(":")
    return kinds[kind] | (int(layer) if layer else 0)


# A tissue file loaded at run time (issue 65): a stack calibrated by `needle calibrate
# --trials` on a rig trial, with a family member, a softening and Prony terms.
CALIBRATED = os.path.join(nh.SET_DIR, "calibrated", "rig_skin_2mmps_t1.toml")


@pytest.mark.parametrize("stack", nh.stack_names() + [CALIBRATED])
def test_insertion_matches_the_library_cli_tick_by_tick(stack, tmp_path):
    poses = trajectory()
    got = nh.Insertion(stack).run(poses)
    want = needle_cli(poses, stack, tmp_path)
    assert len(want) == poses.shape[0]
    want_w = np.array([[np.float32(r[c]) for c in nh.COMPONENTS] for r in want], dtype=np.float32)
    differ = np.flatnonzero((want_w.view(np.uint32) != got.wrench.view(np.uint32)).any(axis=1))
    assert differ.size == 0, f"{differ.size} ticks differ, first tick {differ[0]}: {want[differ[0]]} vs {got.wrench[differ[0]]}"
    np.testing.assert_array_equal(got.status, [int(r["status"], 16) for r in want])
    np.testing.assert_array_equal(got.punctures, [int(r["punctures"]) for r in want])
    np.testing.assert_array_equal(got.phase, [phase_code(r["phase"]) for r in want])
    assert got.punctures.sum() >= 1, "the path punctures"


def test_state_carries_over_between_calls_and_reset_forgets_it():
    poses = trajectory()
    whole = nh.Insertion("liver").run(poses)
    ins = nh.Insertion("liver")
    a, b = ins.run(poses[:5000]), ins.run(poses[5000:])
    np.testing.assert_array_equal(np.concatenate([a.wrench, b.wrench]).view(np.uint32), whole.wrench.view(np.uint32))
    ins.reset()
    again = ins.run(poses)
    np.testing.assert_array_equal(again.wrench.view(np.uint32), whole.wrench.view(np.uint32))


def test_bad_stack_and_config_are_value_errors():
    with pytest.raises(ValueError, match='stack "kidney": no such tissue file, nor a stack of the compiled-in set.*liver'):
        nh.Insertion("kidney")
    with pytest.raises(ValueError, match="cannot read the tissue file"):
        nh.Insertion("/nonexistent/kidney.toml")


def test_a_bad_tissue_file_is_refused_with_its_line(tmp_path):
    with open(CALIBRATED, encoding="utf-8") as f:
        text = f.read()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("stiffness_scale = ", "stiffness_scale = -", 1), encoding="utf-8")
    line = next(i for i, l in enumerate(bad.read_text(encoding="utf-8").splitlines(), 1) if l.startswith("stiffness_scale = -"))
    with pytest.raises(ValueError, match=f"bad.toml:{line}:.*stiffness_scale"):
        nh.Insertion(str(bad))
    with pytest.raises(ValueError, match="period_s, max_speed_mm_per_s and max_turn_deg_per_s must be finite and > 0"):
        nh.Insertion("liver", period_s=0.0)
    with pytest.raises(ValueError, match="one per layer"):
        nh.Insertion("liver").set_scales([1.0] * 99)


def calibrated_on_three_skin_trials(exe: str, tmp_path) -> str:
    """`needle calibrate --trials` on three skin repeats (read in place from the shared
    rig data): a stack with a spread over its trials."""
    rig = os.path.join(nh.SET_DIR, "..", "..", "..", "shared", "data", "stokes-needle-rig")
    trials = [os.path.join(rig, f"skin_2mmps_0deg_needle2_trial{k}.csv") for k in (1, 2, 3)]
    assert all(os.path.isfile(t) for t in trials), f"the measured rig trials live beside the checkout: {rig}"
    out = tmp_path / "skin.toml"
    args = [exe, "calibrate", "--trials", *trials, "--name", "skin", "--needle-diameter-mm", "1.27", "--write-on-miss"]
    # exit 1 when a goal is missed; --write-on-miss writes the stack all the same
    done = subprocess.run(args + ["--set", nh.SET_DIR, "--out", str(out), "--figure", str(tmp_path / "skin.svg")], capture_output=True, text=True)
    assert done.returncode in (0, 1) and out.is_file(), done.stderr
    return str(out)


def test_a_stack_drawn_in_python_is_the_cli_draw_and_loads(tmp_path):
    """issue 65 item 3: Python draws the tissue `needle stack sample` draws (the same
    stack, spread and seed: the same file, byte for byte), within the spread, and the
    drawn file loads and punctures."""
    exe = os.environ.get("NEEDLE_BIN")
    assert exe and os.path.isfile(exe), "NEEDLE_BIN must name the needle binary (.ci/test-python builds it)"
    stack = calibrated_on_three_skin_trials(exe, tmp_path)
    cli_out, py_out = tmp_path / "cli" / "drawn.toml", tmp_path / "drawn.toml"
    cli_out.parent.mkdir()
    subprocess.run([exe, "stack", "sample", "--stack", stack, "--seed", "7", "--out", str(cli_out)], check=True, capture_output=True)
    text = nh.sample_stack(stack, seed=7, out=py_out)
    assert text == cli_out.read_text(encoding="utf-8")
    assert py_out.read_text(encoding="utf-8") == text
    values = lambda t: [line for line in t.splitlines() if line.startswith("stiffness_scale")]
    assert values(text) != values(open(stack, encoding="utf-8").read()), "the draw moves the fitted scale"
    assert values(text) != values(nh.sample_stack(stack, seed=8, name="drawn")), "another seed draws another tissue"
    got = nh.Insertion(str(py_out)).run(trajectory())
    assert got.punctures.sum() >= 1, "the drawn tissue punctures on the scripted path"


def test_a_bad_spread_is_refused_with_its_line(tmp_path):
    bad = tmp_path / "bad.spread.csv"
    bad.write_text("layer,key,trials,mean,sd\n0,stiffness_scale,3,1.0,-0.5\n", encoding="utf-8")
    out = tmp_path / "never.toml"
    with pytest.raises(ValueError, match="bad.spread.csv:2:"):
        nh.sample_stack(CALIBRATED, seed=1, spread=bad, out=out)
    assert not out.exists(), "nothing written on error"

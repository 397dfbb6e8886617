"""The example scripts run: force_depth.py draws its PNG (matplotlib, Agg), timing.py
prints its ratios on a small count."""
import os
import subprocess
import sys

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")


def test_force_depth_writes_its_png(tmp_path):
    out = tmp_path / "force_depth.png"
    subprocess.run([sys.executable, os.path.join(EXAMPLES, "force_depth.py"), str(out)], check=True)
    assert out.stat().st_size > 10_000


def test_timing_prints_its_ratios():
    exe = os.environ["NEEDLE_BIN"]
    run = subprocess.run([sys.executable, os.path.join(EXAMPLES, "timing.py"), "--n", "20000", "--repeat", "1", "--needle", exe], check=True, capture_output=True, text=True)
    assert "ratio binding / NumPy-only" in run.stdout and "bit-identical to the binding: True" in run.stdout, run.stdout

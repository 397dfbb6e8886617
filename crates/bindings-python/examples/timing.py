"""1,000,000 poses: the binding (the library's Rust evaluator) side by side with the
NumPy-only evaluation of the same model (needle_haptics.numpy_model) and with the
library's command line (`needle eval --poses`, CSV in and out), on this machine.
Prints each time (best of `--repeat`) and the ratios; nothing here is typed in.

    python crates/bindings-python/examples/timing.py [--n 1000000] [--repeat 5] [--needle target/release/needle]
"""
import argparse
import os
import subprocess
import tempfile
import time

import numpy as np

import needle_haptics as nh
from needle_haptics.numpy_model import NumpyModel

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, default=1_000_000)
ap.add_argument("--repeat", type=int, default=5)
ap.add_argument("--needle", default=os.environ.get("NEEDLE_BIN", "target/release/needle"))
args = ap.parse_args()

rng = np.random.default_rng(40)
lo = np.array([-12, -12, -15, -15, 0], dtype=np.float32)
hi = np.array([12, 12, 15, 15, 6], dtype=np.float32)
poses = (lo + (hi - lo) * rng.random((args.n, 5), dtype=np.float32)).astype(np.float32)


def best(f, repeat):
    """(best wall s, median wall s, CPU s of the best run, last result)."""
    times = []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        out = f()
        times.append((time.perf_counter() - t0, time.process_time() - c0))
    wall = sorted(t for t, _ in times)
    return wall[0], float(np.median(wall)), min(times)[1], out


t_bind, m_bind, c_bind, (w_bind, _) = best(lambda: nh.wrench(poses), args.repeat)
t_stiff, m_stiff, c_stiff, _ = best(lambda: nh.wrench_and_stiffness(poses), args.repeat)
model = NumpyModel.load()
t_np, m_np, c_np, (w_np, _) = best(lambda: model.wrench(poses), max(1, args.repeat // 2))
same = bool((w_bind.view(np.uint32) == w_np.view(np.uint32)).all())

with tempfile.TemporaryDirectory() as d:
    path = os.path.join(d, "poses.csv")
    # 9 significant digits name every float32 exactly
    np.savetxt(path, poses, delimiter=",", fmt="%.9g", header=",".join(nh.POSE_COLUMNS), comments="")
    t0 = time.perf_counter()
    subprocess.run([args.needle, "eval", "--set", nh.SET_DIR, "--poses", path, "--out", os.path.join(d, "out.csv")], check=True)
    t_cli = time.perf_counter() - t0

print(f"poses: {args.n:,} float32 (n, 5), cores: {os.cpu_count()}, load average {os.getloadavg()[0]:.2f}")
print(f"binding wrench                 best {t_bind:.3f} s  median {m_bind:.3f} s  CPU {c_bind:.3f} s ({c_bind / args.n * 1e9:.0f} ns/pose)")
print(f"binding wrench_and_stiffness   best {t_stiff:.3f} s  median {m_stiff:.3f} s  CPU {c_stiff:.3f} s")
print(f"NumPy-only model               best {t_np:.3f} s  median {m_np:.3f} s  CPU {c_np:.3f} s  (bit-identical to the binding: {same})")
print(f"needle eval --poses (CSV)      once {t_cli:.3f} s")
print(f"ratio binding / NumPy-only     {t_bind / t_np:.3f}")
print(f"ratio binding / needle eval    {t_bind / t_cli:.4f}")
print(f"goal <= 0.3 s per 1,000,000 poses: {'met' if t_bind * 1_000_000 / args.n <= 0.3 else 'missed'}")

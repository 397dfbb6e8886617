"""Force against depth: the model's axial force Fy (the library, through the binding)
along the centre FE run's depths and past them, the FE points on top, and the insertion
model through the liver stack on the same axis. Writes force_depth.png.

    python crates/bindings-python/examples/force_depth.py [out.png]
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import needle_haptics as nh

out = sys.argv[1] if len(sys.argv) > 1 else "force_depth.png"
fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4))

# The surrogate over its domain (0..6 mm) at the centre and at two offsets, with FE runs.
runs = nh.fe_runs()
for name in ["centre", "x+04", "tz+08"]:
    run = runs.get(name)
    if run is None:
        continue
    poses = np.zeros((200, 5), dtype=np.float32)
    poses[:, :4] = (run.x_mm, run.z_mm, run.theta_x_deg, run.theta_z_deg)
    poses[:, 4] = np.linspace(0, 6, 200, dtype=np.float32)
    wrench, _ = nh.wrench(poses)
    (line,) = ax.plot(poses[:, 4], wrench[:, 1], label=f"model, {name}")
    ax.plot(run.depth_mm, run.wrench[:, 1], "o", ms=3, color=line.get_color(), label=f"FE, {name}")
ax.set_xlabel("depth_mm")
ax.set_ylabel("fy_n (N)")
ax.set_title(f"surrogate, set {nh.SET}")
ax.legend(fontsize=7)

# A whole insertion at 1 kHz: in to 40 mm in 8 s, out again.
depth = np.concatenate([np.linspace(-1, 40, 8000), np.linspace(40, -1, 8000)]).astype(np.float32)
poses = np.zeros((depth.size, 5), dtype=np.float32)
poses[:, 4] = depth
stack = nh.stack_names()[0]
t = nh.Insertion(stack).run(poses)
ax2.plot(depth, t.wrench[:, 1], lw=0.8)
ax2.set_xlabel("depth_mm")
ax2.set_ylabel("fy_n (N)")
ax2.set_title(f"insertion through '{stack}' ({int(t.punctures.sum())} punctures)")
fig.tight_layout()
fig.savefig(out, dpi=120)
print(f"wrote {out}")

#!/usr/bin/env python3
"""Times the portable module against the development one on the same solver work, and checks
they compute the same smoke. Each module runs in a process of its own (both are `_native`).

    python3 cmake/portable/compare_speed.py [DEV_DIR] [PORTABLE_DIR] [--resolution N] [--frames N]

Defaults: build/native (Debian's gcc 12, shared OpenVDB/oneTBB) and build-portable/modules (zig's
clang 18, static libraries, glibc 2.28). The scene: a point emitter of smoke and heat at the
bottom of an N³ domain with the solver's default numerics, N frames, the best of 3 runs per
module (alternating), in Debian's /usr/bin/python3 (CPython 3.11, numpy). Prints seconds per frame of each and the largest density difference."""

import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

CHILD = r"""
import json, sys, time
import numpy as np
sys.path.insert(0, sys.argv[1])
import _native
n, frames = int(sys.argv[2]), int(sys.argv[3])
p = _native.SmokeParams()
p.resolution = (n, n, n)
p.cell_size = 1.0 / n
p.origin = (-0.5, -0.5, 0.0)
s = _native.SmokeSolver(p)
f32 = lambda *rows: np.array(rows, dtype=np.float32)
s.set_point_emitters(f32([0.0, 0.0, 0.12]), np.array([0.08], np.float32),
                     np.array([0.02], np.float32), f32([0.0, 0.0, 0.5]),
                     np.array([1.0], np.float32))
t0 = time.perf_counter()
for _ in range(frames):
    s.advance_frame()
elapsed = time.perf_counter() - t0
d = s.get_density()
print(json.dumps({"seconds": elapsed, "density_sum": float(d.sum(dtype=np.float64)),
                  "density": d.ravel()[::97].tolist()}))
"""


def run(module_dir, n, frames):
    out = subprocess.run(["/usr/bin/python3", "-c", CHILD, module_dir, str(n), str(frames)],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dev", nargs="?", default=os.path.join(ROOT, "build", "native"))
    ap.add_argument("portable", nargs="?", default=os.path.join(ROOT, "build-portable", "modules"))
    ap.add_argument("--resolution", type=int, default=64)
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args(argv)
    best = {}
    for _ in range(a.runs):
        for name, folder in (("development", a.dev), ("portable", a.portable)):
            r = run(folder, a.resolution, a.frames)
            if name not in best or r["seconds"] < best[name]["seconds"]:
                best[name] = r
    for name, r in best.items():
        print(f"{name:12s} {r['seconds'] / a.frames * 1000:8.1f} ms/frame "
              f"({a.resolution}^3, {a.frames} frames, best of {a.runs}); "
              f"density sum {r['density_sum']:.6g}")
    dev, port = best["development"], best["portable"]
    diff = max(abs(x - y) for x, y in zip(dev["density"], port["density"]))
    print(f"portable / development time: {port['seconds'] / dev['seconds']:.2f}; "
          f"largest density difference (every 97th cell): {diff:.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

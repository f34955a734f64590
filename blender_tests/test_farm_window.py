"""Scene Properties › Plume Farm in a real window (Debian's Blender 3.4.1 under Xvfb: the bpy
wheels have no window), on the single-node Slurm cluster of test_farm.py: Submit pressed as its
button does (ui/farm_window.py), then the panel's background poll follows the job, queued then
done, the panel draws each state, and Blender's event loop never stalls while it does.

Run: python3 blender_tests/run.py --blender 3.4 test_farm_window.py
"""

import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import run  # noqa: E402
from test_farm import WAIT_S, ClusterTest, shot  # noqa: E402

#: ui/farm_window.py's timer ticks every TICK_S. The windowed Blender's squeue answers after
#: SQUEUE_DELAY_S, as a busy controller's does (a wrapper first on its PATH; the one-machine
#: cluster's own answers in 20-100 ms, too fast to tell a wait from a redraw), so a squeue waited
#: for in the event loop would hold a tick back by two seconds. MAX_STALL_S: the longest gap between
#: two ticks that is not such a wait; measured 0.10-0.39 s (3.4.1 under Xvfb, 2 cores, with and
#: without a build running beside it); with the poll made to wait for squeue, the test fails.
TICK_S, SQUEUE_DELAY_S, MAX_STALL_S = 0.05, 2.0, 1.0
#: The job's tasks when it has ended well (a wedge of one variant).
DONE = [["variants", "DONE"], ["contact_sheet", "DONE"]]


class FarmWindowTest(ClusterTest):
    TMP_PREFIX = "plume_farm_window_"

    def test_the_panel_in_a_window_submits_and_follows_the_job(self):
        """Scene Properties › Plume Farm in a real window (Xvfb, ui/farm_window.py): Submit
        pressed as its button does, then the panel's background poll follows the job (queued or
        running, then done) and the panel draws each state, while Blender's event loop never
        stalls: squeue runs in the background, never in a redraw or a timer's wait."""
        if shutil.which("xvfb-run") is None:
            raise RuntimeError("xvfb-run is missing: install the 'xvfb' package")
        base = os.path.join(self.tmp, "window")
        dom = shot(base, frames=4)
        farm = bpy.context.scene.plume_farm
        farm.job, farm.wedge_domain, farm.wedge_frame = 'WEDGE', dom, 4
        farm.wedge_settings = "seed = 3"
        bpy.ops.wm.save_mainfile()
        result = os.path.join(base, "window.json")
        # The variant's bake holds at its second frame until the window has shown it running
        # (farm_window.py makes the gate file then; the bake goes on by itself after 10 s), so
        # the job cannot end before the first poll, whatever the machine's speed.
        gate = os.path.join(base, "gate")
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path,
               "--factory-startup", os.path.join(base, "shot.blend"),
               "--python", os.path.join(HERE, "ui", "farm_window.py"), "--", result, gate]
        slow = os.path.join(base, "slow_squeue")
        os.makedirs(slow)
        with open(os.path.join(slow, "squeue"), "w", encoding="utf-8") as f:
            f.write(f"#!/bin/sh\nsleep {SQUEUE_DELAY_S}\nexec {shutil.which('squeue')} \"$@\"\n")
        os.chmod(os.path.join(slow, "squeue"), 0o755)
        env = dict(os.environ, PATH=slow + os.pathsep + os.environ["PATH"],
                   PLUME_JOB_GATE=f"{gate}@2")
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=WAIT_S + 60, env=env)
        if not os.path.isfile(result):
            self.fail(f"the windowed Blender wrote no result (rc {proc.returncode}):\n"
                      + (proc.stdout + proc.stderr)[-3000:])
        with open(result, encoding="utf-8") as f:
            rec = json.load(f)
        self.assertEqual(rec["error"], "", rec["error"])
        self.assertEqual(rec["submitted"], ["FINISHED"], (proc.stdout + proc.stderr)[-3000:])
        polled = [p for p in rec["polled"] if p is not None]
        print(f"  window: Submit took {rec['submit_s']:.2f} s; the panel's poll saw {polled}")
        self.assertEqual(polled[-1], DONE, "the job did not end done")
        self.assertTrue(any(p != DONE for p in polled),
                        "the poll never saw the job queued or running")
        ticks = np.diff(rec["ticks"])
        print(f"  window: {len(ticks)} ticks of {TICK_S} s, the longest gap {ticks.max():.3f} s")
        self.assertLess(float(ticks.max()), MAX_STALL_S, "Blender's event loop stalled")
        drawn = [d for d in rec["drawn"] if d is not None]
        self.assertTrue(drawn, "the panel never drew the job's state")
        self.assertEqual(drawn[-1], DONE, "the panel never drew the end")
        self.assertTrue(any(d != DONE for d in drawn),
                        "the panel never drew the job before its end")
        self.assertTrue(os.path.isfile(os.path.join(rec["folder"], "wedge", "contact_sheet.png")))


if __name__ == "__main__":
    run(FarmWindowTest)

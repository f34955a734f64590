"""The UI path of plume.bake: worker thread, modal progress, Esc cancels within one step.

Modal operators, timers and events never run under ``blender -b``, so this test (itself run with
``blender -b`` like the others) starts a real windowed Blender under Xvfb with
``--enable-event-simulate`` on ``ui/bake_modal_esc.py``, which invokes the bake from the
Properties editor, presses Esc after three frames and reports what happened.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_ui_bake.py
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import run  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


class UiBakeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if shutil.which("xvfb-run") is None:
            raise RuntimeError("xvfb-run is missing: install the 'xvfb' package (.ci/common.sh does)")
        fd, cls.result_path = tempfile.mkstemp(suffix=".json", prefix="plume_ui_")
        os.close(fd)
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path,
               "--factory-startup", "--enable-event-simulate",
               "--python", os.path.join(HERE, "ui", "bake_modal_esc.py"), "--", cls.result_path]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=400)
        with open(cls.result_path) as f:
            text = f.read()
        if not text:
            raise RuntimeError(f"the windowed Blender wrote no result (rc {proc.returncode}):\n"
                               + proc.stdout[-3000:] + proc.stderr[-3000:])
        cls.result = json.loads(text)

    def test_no_error(self):
        self.assertNotIn("error", self.result, self.result.get("error"))

    def test_invoke_runs_modal_on_a_worker_thread(self):
        self.assertEqual(self.result["invoke"], ["RUNNING_MODAL"])
        # Blender kept handling timers while the bake ran: a poll saw it mid-bake (invoke had
        # returned, frames were done, more were to come).
        baking = [s for s in self.result["seen"] if s[2] and 0 < s[1] < self.result["total"]]
        self.assertGreaterEqual(len(baking), 1, self.result["seen"])

    def test_esc_cancels_within_one_step_and_keeps_finished_frames(self):
        r = self.result
        self.assertLess(r["done_after"], r["total"])
        # Esc stops the bake within the step in flight: the modal handler's cancel() records
        # how many frames were complete; at most the frame whose files were being written then
        # completes after it, the frame being simulated is dropped. (No wall-clock bound and no
        # bound from the poll that pressed Esc: on a busy machine the event loop may turn late.)
        self.assertTrue(r["cancelled"])
        self.assertIsNotNone(r["done_at_cancel"])
        self.assertGreaterEqual(r["done_at_cancel"], r["done_at_esc"])
        self.assertLessEqual(r["done_after"] - r["done_at_cancel"], 1)
        self.assertEqual(len(r["vdb_files"]), r["done_after"])
        self.assertEqual(r["volume_frames"], r["done_after"])


if __name__ == "__main__":
    run(UiBakeTest)

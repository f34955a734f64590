"""The UI path of Plume's jobs: invoked from a button they run modal on a worker thread with
status-bar progress, Esc cancels them, and deleting the domain, loading another file or quitting
Blender stops them cleanly. A job forecast to be long asks first: a dialog, whose OK starts it
in the background and whose Esc starts nothing.

Modal operators, timers and events never run under ``blender -b``, so this test (itself run with
``blender -b`` like the others) starts one real windowed Blender under Xvfb with
``--enable-event-simulate`` on ``ui/job_modal.py``, which runs the CASES below in order (quit
last) and reports what it saw.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_ui_jobs.py
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import run, tree_listing  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = ["bake:esc", "surfaces:esc", "toon:esc", "surfaces:delete", "surfaces:decline",
         "surfaces:ask", "toon:load", "toon:quit"]
#: Esc, a deleted object or a file load stops a job within one unit of work (a frame, a
#: density map) plus a poll of the modal timer: well under a second on these small scenes.
STOP_S = 1.0
#: The status bar: "<label> i of N, ~s left", or "<label>..." while N is not known yet.
STATUS = re.compile(r"^Plume [A-Za-z ]+: (.+ \d+ of \d+(, ~\d+ s left)?|.+\.\.\.) "
                    r"\(Esc cancels\)$")


class UiJobsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if shutil.which("xvfb-run") is None:
            raise RuntimeError("xvfb-run is missing: install the 'xvfb' package "
                               "(.ci/common.sh does)")
        fd, path = tempfile.mkstemp(suffix=".json", prefix="plume_ui_")
        os.close(fd)
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path,
               "--factory-startup", "--enable-event-simulate",
               "--python", os.path.join(HERE, "ui", "job_modal.py"), "--", path, *CASES]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        cls.output = proc.stdout[-4000:] + proc.stderr[-4000:]
        cls.returncode = proc.returncode
        with open(path) as f:
            text = f.read()
        os.remove(path)
        if not text:
            raise RuntimeError(f"the windowed Blender wrote no result (rc {proc.returncode}):\n"
                               + cls.output)
        cls.result = json.loads(text)
        cls.cases = {(c["operator"], c["action"]): c for c in cls.result["cases"]}
        for c in cls.result["cases"]:
            print(f"  {c['operator']}:{c['action']}: action at unit {c.get('done_at_action')}, "
                  f"cancelled {c.get('seconds_to_cancel') or float('nan'):.2f} s, worker ended "
                  f"{c.get('seconds_worker_ran_on') or float('nan'):.2f} s, job ended "
                  f"{c.get('seconds_to_stop', float('nan')):.2f} s after it; "
                  f"last status: {next((s[4] for s in reversed(c['seen']) if s[4]), '')!r}")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.result.get("tmp", ""), ignore_errors=True)

    def case(self, operator, action):
        self.assertNotIn("error", self.result, self.result.get("error"))
        c = self.cases.get((operator, action))
        self.assertIsNotNone(c, f"case {operator}:{action} did not run:\n{self.output}")
        return c

    def assert_ran_modal_with_progress(self, c):
        """Invoked from the Properties editor: the operator returned RUNNING_MODAL at once, the
        job ran on a thread of its own while Blender kept handling timers, and the status bar
        said "<label> i of N, ~s left (Esc cancels)"."""
        self.assertEqual(c["invoke"], ["RUNNING_MODAL"])
        self.assertFalse(c["worker_is_main_thread"])
        mid = [s for s in c["seen"] if s[2] > 0 and 0 < s[1] < s[2]]
        self.assertGreaterEqual(len(mid), 1, c["seen"])
        statuses = [s[4] for s in c["seen"] if s[4]]
        self.assertTrue(statuses, c["seen"])
        for text in statuses:
            self.assertRegex(text, STATUS)
        self.assertTrue(any("s left" in t for t in statuses), statuses)

    def assert_left_nothing(self, c):
        """No new object, and no new or partial file in the cache folder."""
        self.assertEqual(c["objects_after"], [n for n in c["objects_before"]
                                              if c["action"] != "delete" or n != "Domain"])
        self.assertEqual(c["files_after"], c["files_before"])

    # ------------------------------------------------------------------ Esc
    def test_bake_esc_keeps_finished_frames(self):
        c = self.case("bake", "esc")
        self.assert_ran_modal_with_progress(c)
        self.assertLess(c["done_after"], c["total"])
        # Esc stops the bake within the step in flight: cancel() records how many frames were
        # complete; at most the frame whose files were being written then completes after it.
        self.assertTrue(c["cancelled"])
        self.assertIsNotNone(c["done_at_cancel"])
        self.assertGreaterEqual(c["done_at_cancel"], c["done_at_action"])
        self.assertLessEqual(c["done_after"] - c["done_at_cancel"], 1)
        self.assertEqual(len(c["vdb_files"]), c["done_after"])
        self.assertEqual(c["volume_frames"], c["done_after"])

    def test_surfaces_esc_leaves_nothing(self):
        c = self.case("surfaces", "esc")
        self.assertEqual(c["job_title"], "Build Surfaces")
        self.assert_ran_modal_with_progress(c)
        self.assert_left_nothing(c)
        self.assertLess(c["seconds_to_stop"], STOP_S)

    def test_toon_esc_leaves_nothing(self):
        c = self.case("toon", "esc")
        self.assertEqual(c["job_title"], "Build Toon Smoke")
        self.assert_ran_modal_with_progress(c)
        self.assert_left_nothing(c)
        self.assertLess(c["seconds_to_stop"], STOP_S)

    # ------------------------------------------------------------------ a long job asks first
    def test_long_job_declined_starts_nothing(self):
        c = self.case("surfaces", "decline")
        self.assertEqual(c["invoke"], ["RUNNING_MODAL"])  # the dialog is open
        self.assertFalse(c["job_before_answer"])
        self.assertIsNone(c["job_title"])
        self.assert_left_nothing(c)

    def test_long_job_confirmed_runs_in_the_background(self):
        c = self.case("surfaces", "ask")
        self.assertEqual(c["invoke"], ["RUNNING_MODAL"])
        self.assertFalse(c["job_before_answer"])  # nothing ran before the answer
        self.assertEqual(c["job_title"], "Build Surfaces")
        self.assertFalse(c["worker_is_main_thread"])
        self.assertTrue(any(s[4] for s in c["seen"]), c["seen"])
        new = sorted(set(c["objects_after"]) - set(c["objects_before"]))
        self.assertTrue(new and all("_surface_" in n for n in new), new)

    # ------------------------------------------------------------------ from outside
    def test_deleting_the_domain_cancels(self):
        c = self.case("surfaces", "delete")
        self.assert_ran_modal_with_progress(c)
        self.assert_left_nothing(c)
        self.assertLess(c["seconds_to_stop"], STOP_S)

    def test_loading_a_file_cancels(self):
        c = self.case("toon", "load")
        self.assertEqual(c["files_after"], c["files_before"])
        self.assertLess(c["seconds_to_stop"], STOP_S)

    def test_quitting_cancels(self):
        c = self.case("toon", "quit")
        self.assertTrue(self.result.get("quitting"), self.result)
        self.assertEqual(self.returncode, 0, self.output)
        self.assertNotIn("Traceback", self.output)
        self.assertEqual(tree_listing(c["cache"]), c["files_before"])


if __name__ == "__main__":
    run(UiJobsTest)

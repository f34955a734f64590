"""The UI path of Plume's jobs, and what an artist may do while one runs. Invoked from a button,
every long operator (Bake, Bake Flames, Build Toon Smoke, Build Surfaces, Synthesize Fire, Build
Flow Graph) runs modal, its work in a child process, with status-bar progress; while it runs the artist
presses Esc, opens another file, undoes and redoes, deletes or renames the object it works on,
changes its settings, presses its pipeline's Free, saves the file, or quits Blender. Blender
never crashes or hangs, and:

    esc, load, delete, rename   the job stops within a second; nothing is built and no file is
                                new or partial (a bake keeps its complete frames, which resume)
    undo, redo, settings,       the job goes on to its end and builds its result from the
    free, save                  snapshot it took when it started (new settings apply to the
                                next run); Free is refused while the job runs; the file saved
                                holds the scene as it was (no half-built object)
    quit                        Blender exits 0 with no traceback; the cache folder is as before
                                (a bake: its complete frames, which a later bake resumes to a
                                result bit-identical, grid by grid, to a straight bake)

Modal operators, timers and events never run under ``blender -b``, so this test (itself run with
``blender -b`` like the others) starts real windowed Blenders under Xvfb with
``--enable-event-simulate`` on ``ui/job_modal.py``: one runs every case but the quits in order,
then one per quit case (quitting ends the process).

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
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "ui")]

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import native, pid_alive, reset_scene, run, select_only, tree_listing  # noqa: E402
import job_cases  # noqa: E402

OPERATORS = ("bake", "flames", "toon", "surfaces", "synth", "graph")
TITLES = {"bake": "Bake", "flames": "Bake Flames", "toon": "Build Toon Smoke",
          "surfaces": "Build Surfaces", "synth": "Synthesize Fire", "graph": "Build Flow Graph"}
STOPPING = ("esc", "load", "delete", "rename")
GOING_ON = ("undo", "redo", "settings", "free", "save")
CASES = [f"{o}:{a}" for o in OPERATORS for a in STOPPING + GOING_ON] + \
    ["surfaces:decline", "surfaces:ask"]
#: One process each. quit0: the operator's wait for its child cut to 0 s, so the child is
#: killed and not reaped before Blender tears down (it must not outlive Blender all the same).
QUITS = [f"{o}:quit" for o in OPERATORS] + ["bake:undo+quit", "bake:free+quit", "bake:quit0"]
#: Esc, a deleted or renamed object or a file load stops a job within one unit of work (a
#: frame, a surface, a density map, a slice of the cost matrix) plus a poll of the modal timer
#: (and, for load, the file's own reading): measured 0.2-1.0 s on these small scenes, 1.7 s for
#: a file load during a flames frame (0.5-0.7 s) with another windowed Blender running. The
#: outcome says the job stopped; this bound, twice the slowest, that it did not hang on.
STOP_S = 3.5
#: The status bar: "<label> i of N, ~s left", or "<label>..." while N is not known yet.
STATUS = re.compile(r"^Plume [A-Za-z ]+: (.+ \d+ of \d+(, ~\d+ s left)?|.+\.\.\.) "
                    r"\(Esc cancels\)$")
#: What may never appear in a windowed Blender's output.
CRASH = re.compile(r"Traceback|terminate called|Segmentation fault|Aborted")


def windowed(tmp, result, cases):
    """Runs job_modal.py on `cases` in a windowed Blender under Xvfb: (exit code, output,
    the result dict)."""
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path,
           "--factory-startup", "--enable-event-simulate",
           "--python", os.path.join(HERE, "ui", "job_modal.py"), "--", result, tmp, *cases]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    output = proc.stdout + proc.stderr
    text = open(result).read() if os.path.isfile(result) else ""
    if not text:
        raise RuntimeError(f"the windowed Blender wrote no result (rc {proc.returncode}):\n"
                           + output[-4000:])
    return proc.returncode, output, json.loads(text)


def grids(folder):
    """{file: {grid: (min, voxel size, values)}} of every VDB frame in `folder`."""
    n, out = native(), {}
    for name in sorted(f for f in os.listdir(folder) if f.endswith(".vdb")):
        path = os.path.join(folder, name)
        out[name] = {g: n.read_vdb_grid(path, g) for g in n.vdb_grid_names(path)}
    return out


def bake_blocking(cache):
    """The bake cases' scene in `cache`, baked (resumed when frames are there) blocking."""
    reset_scene()
    select_only(job_cases.bake_scene_in(cache))
    assert bpy.ops.plume.bake() == {'FINISHED'}
    return os.path.join(cache, "Domain")


class UiJobsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if shutil.which("xvfb-run") is None:
            raise RuntimeError("xvfb-run is missing: install the 'xvfb' package "
                               "(.ci/common.sh does)")
        cls.tmp = tempfile.mkdtemp(prefix="plume_ui_")
        t0 = time.perf_counter()
        rc, out, res = windowed(cls.tmp, os.path.join(cls.tmp, "matrix.json"), CASES)
        cls.returncode, cls.output, cls.result = rc, out, res
        cls.cases = {(c["operator"], c["action"]): c for c in res["cases"]}
        for c in res["cases"]:
            print(f"  {c['operator']}:{c['action']}: at unit {c.get('done_at_action')}, "
                  f"{c.get('outcome') or 'nothing ran'}, ended "
                  f"{c.get('seconds_to_stop', float('nan')):.2f} s after; "
                  f"{c.get('report', '')[:90]}")
        print(f"  {len(CASES)} cases in one windowed Blender: {time.perf_counter() - t0:.0f} s")
        cls.quits = {}
        for case in QUITS:
            t0 = time.perf_counter()
            rc, out, res = windowed(cls.tmp, os.path.join(cls.tmp, f"{case}.json"), [case])
            cls.quits[case] = (rc, out, res)
            c = res["cases"][-1] if res["cases"] else {}
            print(f"  {case}: quit at unit {c.get('done_at_quit', c.get('done_at_action'))}, "
                  f"exit code {rc}, the process {time.perf_counter() - t0:.1f} s")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def case(self, operator, action):
        self.assertNotIn("error", self.result, self.result.get("error"))
        c = self.cases.get((operator, action))
        self.assertIsNotNone(c, f"case {operator}:{action} did not run:\n{self.output[-4000:]}")
        return c

    def assert_ran_modal_with_progress(self, c):
        """Invoked from the Properties editor: the operator returned RUNNING_MODAL at once, the
        job ran in a child process while Blender kept handling timers, and the status bar
        said "<label> i of N, ~s left (Esc cancels)"."""
        self.assertEqual(c["job_title"], TITLES[c["operator"]])
        self.assertEqual(c["invoke"], ["RUNNING_MODAL"])
        self.assertTrue(c["ran_in_child"])
        statuses = [s[4] for s in c["seen"] if s[4]]
        self.assertTrue(statuses, c["seen"])
        for text in statuses:
            self.assertRegex(text, STATUS)
        self.assertTrue(any("s left" in t for t in statuses), statuses)

    def assert_consistent(self, c):
        """No staging folder, job file or unfinished write left, the child gone; a bake's frames
        are the manifest's; a flames bake's frames are whole (a VDB and its spines each)."""
        self.assertEqual(c["leftovers"], [])
        self.assertFalse(c.get("child_alive"))
        if c["operator"] == "bake":
            self.assertEqual(len(c["vdb_files"]), c["done_after"])
        if c["operator"] == "flames":
            self.assert_flames_whole(c["cache"])

    def assert_flames_whole(self, folder):
        names = os.listdir(folder)
        vdbs = sorted(n[7:11] for n in names if n.startswith("flames_") and n.endswith(".vdb"))
        npzs = sorted(n[7:11] for n in names if n.startswith("spines_") and n.endswith(".npz"))
        self.assertEqual(vdbs, npzs)
        with open(os.path.join(folder, "flames_manifest.json")) as f:
            last = json.load(f)["last_complete_frame"]
        self.assertEqual(vdbs, [f"{i:04d}" for i in range(1, last + 1)])

    def assert_left_nothing(self, c):
        """No new object; no new or partial file (a bake: its complete frames only)."""
        gone = c["object"] if c["action"] in ("delete", "rename") else None
        self.assertEqual([n for n in c["objects_after"] if not n.endswith(" renamed")],
                         [n for n in c["objects_before"] if n != gone])
        if c["operator"] not in ("bake", "flames"):
            self.assertEqual(c["files_after"], c["files_before"])

    # ------------------------------------------------------------------ the job stops
    def test_stopping_actions(self):
        for op in OPERATORS:
            for action in STOPPING:
                with self.subTest(f"{op}:{action}"):
                    c = self.case(op, action)
                    self.assert_ran_modal_with_progress(c)
                    outcome = {"esc": "cancelled", "load": "aborted"}.get(action, "gone")
                    self.assertEqual(c["outcome"], outcome, c["report"])
                    self.assertLess(c["seconds_to_stop"], STOP_S)
                    self.assert_consistent(c)
                    if action != "load" and not (action == "esc" and op in ("bake", "flames")):
                        self.assert_left_nothing(c)
                    if action == "load":  # the other file's objects; the cache as it was
                        self.assertEqual(c["objects_after"], c["objects_before"])
                        if op not in ("bake", "flames"):
                            self.assertEqual(c["files_after"], c["files_before"])

    def test_bake_esc_keeps_finished_frames(self):
        c = self.case("bake", "esc")
        self.assertLess(c["done_after"], c["total"])
        # Esc stops the bake within the step in flight: cancel() records how many frames were
        # complete; at most the frame whose files were being written then completes after it.
        self.assertTrue(c["cancelled"])
        self.assertGreaterEqual(c["done_at_cancel"], c["done_at_action"])
        self.assertLessEqual(c["done_after"] - c["done_at_cancel"], 1)
        self.assertEqual(c["volume_frames"], c["done_after"])

    # ------------------------------------------------------------------ the job goes on
    def test_going_on_actions(self):
        for op in OPERATORS:
            finished = [self.case(op, a) for a in GOING_ON]
            for c in finished:
                with self.subTest(f"{op}:{c['action']}"):
                    self.assert_ran_modal_with_progress(c)
                    self.assertEqual(c["outcome"], "finished", c["report"])
                    self.assert_consistent(c)
                    if op != "graph":  # the graph is a file and the panel's image
                        self.assertGreater(len(c["objects_after"]), len(c["objects_before"]))
            # The same result whatever happened meanwhile: the report without its timing
            # (undo/redo replaced every datablock; settings changed; Free refused; saved).
            reports = {re.sub(r"[\d.]+ s(/frame)?\b.*", "", c["report"]) for c in finished}
            self.assertEqual(len(reports), 1, reports)

    def test_undo_redo(self):
        for op in OPERATORS:
            with self.subTest(op):
                undo, redo = self.case(op, "undo"), self.case(op, "redo")
                self.assertEqual((undo["undo"], undo["marker_x"]), (["FINISHED"], 0.0))
                self.assertEqual((redo["redo"], redo["marker_x"]), (["FINISHED"], 1.0))

    def test_settings_changed_meanwhile(self):
        """The job's result is the snapshot's: the bake's manifest still has 40³; the flame
        lights use the Light Unit the emission grids were baked with, not the new one."""
        c = self.case("bake", "settings")
        self.assertEqual(c["resolution"], [job_cases.BAKE_RESOLUTION] * 3)
        self.assertEqual(c["done_after"], c["total"])
        c = self.case("flames", "settings")
        self.assertIsNotNone(c["lights_light_unit"])
        self.assertEqual(c["lights_light_unit"], c["baked_light_unit"])

    def test_free_is_refused(self):
        for op in OPERATORS:
            with self.subTest(op):
                c = self.case(op, "free")
                self.assertRegex(c["free"], r"^Error: Plume: .*(busy|baking).*cancel")

    def test_save_holds_no_half_built_object(self):
        for op in OPERATORS:
            with self.subTest(op):
                c = self.case(op, "save")
                self.assertEqual(c["save"], ["FINISHED"])
                self.assertTrue(os.path.isfile(c["saved_file"]))
                self.assertEqual(c["objects_at_save"], c["objects_before"])

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
        self.assertTrue(c["ran_in_child"])
        new = sorted(set(c["objects_after"]) - set(c["objects_before"]))
        self.assertTrue(new and all("_surface_" in n for n in new), new)

    # ------------------------------------------------------------------ quit
    def test_no_crash_in_the_matrix(self):
        self.assertEqual(self.returncode, 0, self.output[-4000:])
        self.assertIsNone(CRASH.search(self.output), self.output[-4000:])
        self.assertTrue(self.result.get("finished"), self.result.get("error"))

    def test_quitting(self):
        for case, (rc, output, res) in self.quits.items():
            with self.subTest(case):
                self.assertNotIn("error", res, res.get("error"))
                self.assertTrue(res.get("quitting"), res)
                self.assertEqual(rc, 0, output[-4000:])
                self.assertIsNone(CRASH.search(output), output[-4000:])
                c = res["cases"][-1]
                files = tree_listing(c["cache"])
                self.assertEqual(job_cases.leftovers(c["cache"]), [])
                self.assertIsNotNone(c.get("child_pid"), c)
                self.assertFalse(pid_alive(c["child_pid"]), "the job's child outlived Blender")
                if c["operator"] == "flames":
                    self.assert_flames_whole(c["cache"])
                elif c["operator"] != "bake":
                    self.assertEqual(files, c["files_before"])

    def test_bake_resumes_after_quit_bit_identical(self):
        """Each bake quit mid-way, resumed by a blocking bake, ends bit-identical, grid by
        grid, to a straight bake."""
        straight = grids(bake_blocking(tempfile.mkdtemp(prefix="straight_", dir=self.tmp)))
        self.assertEqual(len(straight), job_cases.BAKE_FRAMES)
        for case, (_rc, _out, res) in self.quits.items():
            c = res["cases"][-1]
            if c["operator"] != "bake":
                continue
            with self.subTest(case):
                folder = os.path.join(c["cache"], "Domain")
                kept = sorted(n for n in os.listdir(folder) if n.endswith(".vdb"))
                self.assertLess(len(kept), job_cases.BAKE_FRAMES)  # the quit stopped it
                resumed = grids(bake_blocking(c["cache"]))
                self.assertEqual(sorted(resumed), sorted(straight))
                for name, frame in straight.items():
                    self.assertEqual(sorted(resumed[name]), sorted(frame), name)
                    for g, a in frame.items():
                        b = resumed[name][g]
                        self.assertEqual((a["min"], a["voxel_size"]), (b["min"], b["voxel_size"]))
                        va, vb = np.asarray(a["values"]), np.asarray(b["values"])
                        self.assertEqual(va.shape, vb.shape, f"{name} {g}")
                        self.assertEqual(va.tobytes(), vb.tobytes(), f"{name} {g}")


if __name__ == "__main__":
    run(UiJobsTest)

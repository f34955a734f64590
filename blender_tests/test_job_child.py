"""A job's work runs in a child process, so a crash there costs the job, never Blender
(addon/jobs/process.py, child.py). Faults are injected into the child only, by the environment
variable it reads (PLUME_JOB_FAULT="<what>@<n>": when its progress reaches n units it
segfaults, aborts, is SIGKILLed as the out-of-memory killer does, exits with status 7 or
raises): the operator reports an error naming the job, the cache folder, how the child ended
and the last lines of its log; this Blender goes on with the scene unchanged and no child left
alive; a bake keeps its complete frames and the next Bake resumes bit-identical to a straight
bake. The same job file runs headless with ``python -m plume.job run <cache folder>``, from a
copy of the folder at another path too. A job whose child does not stop at its next unit
(a native call that cannot be cancelled inside: "hang") is killed within a second of Esc.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_job_child.py
"""

import json
import os
import re
import shutil
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import (add_domain, add_sphere_source, assert_same_frames, pid_alive,  # noqa: E402
                     reset_scene, rmtree, run, select_only, temp_dir, tree_listing)

RESOLUTION, FRAMES = 24, 10
GRIDS = ("density", "temperature", "velocity")
FAULT = "PLUME_JOB_FAULT"


def frame_file(folder, frame):
    return os.path.join(folder, f"volume_{frame:04d}.vdb")


def last_complete(folder):
    with open(os.path.join(folder, "manifest.json")) as f:
        return json.load(f)["last_complete_frame"]


class Fault:
    """PLUME_JOB_FAULT set for the calls inside (read by the child only)."""

    def __init__(self, what):
        self.what = what

    def __enter__(self):
        os.environ[FAULT] = self.what

    def __exit__(self, *_exc):
        os.environ.pop(FAULT, None)


class JobChildTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_child_")
        self.cache = os.path.join(self.tmp, "cache")
        self.folder = os.path.join(self.cache, "Domain")
        add_sphere_source()
        self.dom = add_domain(resolution=RESOLUTION, frame_end=FRAMES,
                              cache_directory=self.cache + "/")
        select_only(self.dom)

    def tearDown(self):
        os.environ.pop(FAULT, None)
        from plume.jobs import registry
        self.assertEqual(registry.running(), [])
        rmtree(self.tmp)

    def scene_state(self):
        d = bpy.data
        return dict(objects=sorted(o.name for o in d.objects), volumes=len(d.volumes),
                    meshes=len(d.meshes), materials=len(d.materials),
                    settings=repr(sorted((p.identifier, str(getattr(self.dom.plume.domain,
                                                                     p.identifier)))
                                         for p in self.dom.plume.domain.bl_rna.properties
                                         if p.type in {'INT', 'FLOAT', 'BOOLEAN', 'STRING',
                                                       'ENUM'}
                                         and not getattr(p, "is_array", False))))

    def failing_bake(self, what):
        """Bake with the fault `what`; the error text (the child's pid checked gone)."""
        before = self.scene_state()
        with Fault(what), self.assertRaises(RuntimeError) as cm:
            bpy.ops.plume.bake()
        text = str(cm.exception)
        print(f"  {what}: {text[:400]}")
        self.assertEqual(self.scene_state(), before, "the failed bake changed the scene")
        pid = re.search(r"pid (\d+)", text)
        if pid:
            self.assertFalse(pid_alive(int(pid.group(1))), "the crashed child is still alive")
        return text

    def baked_with_camera(self):
        """The domain baked, with a camera (what Build Toon Smoke needs); the cache's files."""
        bpy.ops.object.camera_add(location=(0.0, -6.0, 1.0), rotation=(1.5708, 0.0, 0.0))
        bpy.context.scene.camera = bpy.context.active_object
        select_only(self.dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        return tree_listing(self.cache)

    def hanging_toon_job(self):
        """A Build Toon Smoke whose child hangs after its first frame (as in a native call
        that cannot be cancelled), started as a button starts it; (job, the cache's files)."""
        from plume.jobs.process import JobProcess
        from plume.operators.toon import ToonJob
        files = self.baked_with_camera()
        job = ToonJob()
        job.prepare(bpy.context)
        with Fault("hang@1"):
            JobProcess(job).start()
        t0 = time.perf_counter()
        while job.progress().done < 1 and time.perf_counter() - t0 < 60:
            job.child.wait(0.05)
        return job, files

    def straight_bake(self):
        """The same scene baked straight into another folder; that folder."""
        straight = os.path.join(self.tmp, "straight")
        dom = add_domain(resolution=RESOLUTION, frame_end=FRAMES, cache_directory=straight + "/",
                         name="Straight")
        select_only(dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        select_only(self.dom)
        return os.path.join(straight, "Straight")

    # ------------------------------------------------------------------ faults
    def test_segfault_costs_the_bake_only_and_it_resumes(self):
        text = self.failing_bake("segv@4")
        self.assertIn("SIGSEGV", text)
        self.assertIn(self.folder, text)
        self.assertRegex(text, r"bake of 'Domain' failed")
        self.assertRegex(text, r"last lines of its log .*jobs/bake\.log: .*injected fault 'segv'"
                               r".*Fatal Python error: Segmentation fault")
        # The complete frames stay (the fault came when frame 4 was reported complete) and the
        # job file and its log are kept for a rerun.
        self.assertEqual(last_complete(self.folder), 4)
        self.assertTrue(os.path.isfile(os.path.join(self.folder, "jobs", "bake.json")))
        self.assertIsNone(bpy.data.objects.get("Domain_volume"))
        # Bake again: it resumes after frame 4 and matches a straight bake bit for bit.
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        with open(os.path.join(self.folder, "manifest.json")) as f:
            m = json.load(f)
        self.assertTrue(m["last_run"]["resumed"])
        self.assertLessEqual(m["last_run"]["computed_frames"][0], 5)
        self.assertEqual(m["last_complete_frame"], FRAMES)
        self.assertFalse(os.path.exists(os.path.join(self.folder, "jobs")))
        assert_same_frames(self, frame_file, self.folder, self.straight_bake(),
                           range(1, FRAMES + 1), GRIDS)

    def test_a_kill_between_a_frame_and_its_manifest_is_tidied(self):
        """A child killed after a frame's file is renamed into place but before the manifest
        names it leaves one frame too many; the job that still holds the folder removes it, so
        the folder holds exactly the manifest's complete frames (bake and flames)."""
        from plume.operators.bake import BakeJob
        from plume.operators.flames import FlamesJob
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        with open(os.path.join(self.folder, "manifest.json")) as f:
            m = json.load(f)
        m["last_complete_frame"] = 6
        with open(os.path.join(self.folder, "manifest.json"), "w") as f:
            json.dump(m, f)
        BakeJob().tidy_partial(self.folder)
        self.assertEqual(sorted(n for n in os.listdir(self.folder) if n.endswith(".vdb")),
                         [f"volume_{i:04d}.vdb" for i in range(1, 7)])
        flames = os.path.join(self.tmp, "flames")
        os.makedirs(flames)
        for i in range(1, 5):
            for name in (f"flames_{i:04d}.vdb", f"spines_{i:04d}.npz"):
                open(os.path.join(flames, name), "w").close()
        with open(os.path.join(flames, "flames_manifest.json"), "w") as f:
            json.dump({"format_version": 1, "kind": "flames", "last_complete_frame": 3}, f)
        FlamesJob().tidy_partial(flames)
        self.assertEqual(sorted(os.listdir(flames)),
                         ["flames_0001.vdb", "flames_0002.vdb", "flames_0003.vdb",
                          "flames_manifest.json", "spines_0001.npz", "spines_0002.npz",
                          "spines_0003.npz"])

    def test_every_way_a_child_ends_is_reported(self):
        """SIGKILL (what the out-of-memory killer sends), an abort in a library, another exit
        status and an exception: each named, the scene unchanged, no child left."""
        cases = (("kill@2", r"SIGKILL \(killed: out of memory, or by another program\)"),
                 ("abort@2", r"SIGABRT \(an abort in a library\)"),
                 ("exit@2", r"exited with status 7"),
                 ("raise@2", r"injected fault .*its log: .*jobs/bake\.log"))
        for what, pattern in cases:
            text = self.failing_bake(what)
            self.assertRegex(text, pattern)
            self.assertGreaterEqual(last_complete(self.folder), 2)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(last_complete(self.folder), FRAMES)

    def test_crashed_build_changes_nothing(self):
        """A job that stages its files (Build Toon Smoke) crashes half way: nothing of it is
        left in the cache folder, and no object was made."""
        self.baked_with_camera()
        # The job file and log a crash keeps (jobs/) are left out: they are the report.
        files = [n for n in tree_listing(self.cache) if "jobs" not in n.split(os.sep)]
        before = self.scene_state()
        with Fault("segv@3"), self.assertRaises(RuntimeError) as cm:
            bpy.ops.plume.toon_build()
        self.assertIn("SIGSEGV", str(cm.exception))
        self.assertIn("nothing was changed", str(cm.exception))
        self.assertEqual(self.scene_state(), before)
        self.assertEqual([n for n in tree_listing(self.cache) if "jobs" not in n.split(os.sep)],
                         files)
        self.assertEqual(bpy.ops.plume.toon_build(), {'FINISHED'})

    def test_disabling_the_addon_ends_the_job(self):
        """Disabling the add-on while a job's child runs kills it and removes what it staged;
        enabled again, the next build works."""
        from helpers import ADDON, enable_addon
        job, files = self.hanging_toon_job()
        bpy.ops.preferences.addon_disable(module=ADDON)
        try:
            self.assertTrue(job.aborted and job.child.finished)
            self.assertFalse(pid_alive(job.child.pid))
            self.assertEqual(tree_listing(self.cache), files)
        finally:
            enable_addon()
        select_only(bpy.data.objects["Domain"])
        self.assertEqual(bpy.ops.plume.toon_build(), {'FINISHED'})

    # ------------------------------------------------------------------ headless
    def test_job_command_runs_the_job_file_anywhere(self):
        """The job file a crashed bake left runs with ``python -m plume.job run <folder>`` (the
        command the UI's child is), in place and from a copy of the cache folder elsewhere;
        both end as a straight bake does, bit for bit."""
        from plume.jobs import process
        self.failing_bake("segv@3")
        moved = os.path.join(self.tmp, "elsewhere", "Domain")
        shutil.copytree(self.folder, moved)
        root, package = process._package()
        env = dict(os.environ, PYTHONPATH=root)
        for folder in (self.folder, moved):
            done = subprocess.run([process.child_python(), "-m", f"{package}.job", "run", folder],
                                  capture_output=True, text=True, env=env, timeout=300)
            print(f"  job command in {folder}: exit {done.returncode}; "
                  f"{done.stdout.strip().splitlines()[-1:]}")
            self.assertEqual(done.returncode, 0, done.stdout[-2000:] + done.stderr[-2000:])
            self.assertEqual(last_complete(folder), FRAMES)
            self.assertFalse(os.path.exists(os.path.join(folder, ".plume.lock")))
        straight = self.straight_bake()
        for folder in (self.folder, moved):
            assert_same_frames(self, frame_file, folder, straight, range(1, FRAMES + 1), GRIDS)
        # A folder with no job: a clear refusal, exit status 2.
        done = subprocess.run([process.child_python(), "-m", f"{package}.job", "run", straight],
                              capture_output=True, text=True, env=env, timeout=60)
        self.assertEqual(done.returncode, 2)
        self.assertIn("expected one job file", done.stderr)

    def test_job_file_round_trip_and_refusals(self):
        """The job file keeps what a spec holds exactly (tuples, dicts with int keys, NaN,
        arrays, the add-on's dataclasses), stores paths inside the cache folder relative to it,
        and a job file from a newer Plume or a damaged one is refused by name."""
        import numpy as np
        from plume.jobs import jobfile
        from plume.settings import SolverSettings
        folder = os.path.join(self.tmp, "jobfolder")
        solver = SolverSettings()
        spec = {"t": (1, 2.5, "x"), "pairs": {3: [1, 2]}, "nan": float("nan"),
                "a": np.arange(6, dtype=np.float32).reshape(2, 3), "solver": solver,
                "inside": os.path.join(folder, "sub", "f.vdb"), "outside": "/elsewhere/f.vdb"}
        path = jobfile.write_job(folder, "bake", "Bake", spec)
        with open(path) as f:
            text = f.read()
        self.assertIn('"__path__": "sub/f.vdb"', text)
        self.assertNotIn(folder, text)
        moved = os.path.join(self.tmp, "moved")
        shutil.copytree(folder, moved)
        header, back, root = jobfile.read_job(os.path.join(moved, "jobs", "bake.json"))
        self.assertEqual((header["kind"], root), ("bake", moved))
        self.assertEqual(back["t"], (1, 2.5, "x"))
        self.assertEqual(back["pairs"], {3: [1, 2]})
        self.assertNotEqual(back["nan"], back["nan"])
        self.assertEqual(back["a"].dtype, np.float32)
        self.assertEqual(back["a"].tolist(), spec["a"].tolist())
        self.assertEqual(back["solver"], solver)
        self.assertEqual(back["inside"], os.path.join(moved, "sub", "f.vdb"))
        self.assertEqual(back["outside"], "/elsewhere/f.vdb")
        with open(path) as f:
            body = json.load(f)
        body["version"] = jobfile.FORMAT_VERSION + 1
        with open(path, "w") as f:
            json.dump(body, f)
        with self.assertRaisesRegex(jobfile.JobFileError, "written by a newer Plume"):
            jobfile.read_job(path)
        with open(path, "w") as f:
            f.write("{not json")
        with self.assertRaisesRegex(jobfile.JobFileError, "cannot be read"):
            jobfile.read_job(path)

    # ------------------------------------------------------------------ Esc
    def test_a_child_that_cannot_stop_is_killed_within_a_second(self):
        """Esc on a job whose child is inside a call that cannot be cancelled (the fault
        "hang": the shot fit, reading streak files or the graph's weights would be the same):
        killed after the grace period, within 1 s of the cancel; nothing changed."""
        from plume.jobs import registry
        job, files = self.hanging_toon_job()
        try:
            time.sleep(0.3)  # inside the hang
            t_cancel = time.perf_counter()
            job.cancel()
            job.child.wait(10.0)
            stopped = time.perf_counter() - t_cancel
        finally:
            registry.abort(job)
        print(f"  killed {stopped:.2f} s after the cancel")
        self.assertTrue(job.child.killed and job.child.finished)
        self.assertLess(stopped, 1.0)
        self.assertFalse(pid_alive(job.child.pid))
        self.assertEqual(tree_listing(self.cache), files)


if __name__ == "__main__":
    run(JobChildTest)

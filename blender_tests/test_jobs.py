"""The job mechanism headless (addon/jobs/): a cancelled job leaves nothing behind, one job per
domain at a time, loading a file aborts a running job, the staging folder commits atomically,
and the process exits cleanly with a job's child still running (jobs_exit.py); no Plume thread
runs in Blender's process.

A 24³ streak bake of 20 frames with a camera is built once; Build Surfaces, Build Toon Smoke and
Export Mesh then run through their operators (blocking, as scripts call them) with a runner
cancelled from its own progress report after a unit or two of work, in run() and in the
main-thread steps: the operator returns CANCELLED, and the scene's datablocks and the cache
folder's files are exactly as before. Flow Graph and Synthesize Fire are cancelled the same way
in test_flowgraph_fire.py.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_jobs.py
"""

import os
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import (assert_reports_error, incense_streak_scene, pid_alive, reset_scene,  # noqa: E402
                     rmtree, run, run_cancelled, select_only, temp_dir, tree_listing)

RESOLUTION = 24
FRAMES = 20


class JobsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_jobs_")
        reset_scene()
        cls.dom = incense_streak_scene(cls.tmp, RESOLUTION, FRAMES)
        assert bpy.ops.plume.bake() == {'FINISHED'}

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def setUp(self):
        select_only(self.dom)

    def tearDown(self):
        from plume.jobs import registry
        self.assertEqual(registry.running(), [], "a job still holds its keys")

    def state(self):
        d = bpy.data
        return dict(objects=sorted(o.name for o in d.objects), meshes=len(d.meshes),
                    curves=len(d.curves), materials=len(d.materials), images=len(d.images),
                    collections=len(d.collections), node_groups=len(d.node_groups),
                    files=tree_listing(self.tmp))

    def assert_cancel_leaves_nothing(self, op_class, make_job, after):
        before = self.state()
        job = make_job()
        self.assertEqual(run_cancelled(op_class, job, after), {'CANCELLED'})
        self.assertTrue(job.cancelled)
        self.assertEqual(self.state(), before)
        return job

    # ------------------------------------------------------------------ cancel
    def test_0_surfaces_cancelled_in_run(self):
        from plume.operators.surfaces import PLUME_OT_surfaces_build, SurfacesJob
        job = self.assert_cancel_leaves_nothing(PLUME_OT_surfaces_build, SurfacesJob, 2)
        self.assertEqual(job.progress().label, "density map of frame")

    def test_1_surfaces_cancelled_in_main_steps(self):
        """Cancelled while the density-map images are saved into the staging folder."""
        from plume.operators.surfaces import PLUME_OT_surfaces_build, SurfacesJob

        def job():
            j = SurfacesJob()
            j.main_steps_seen = []
            steps = j.main_steps

            def counted(context):
                for s in steps(context):
                    j.main_steps_seen.append(j.progress().done)
                    yield s
            j.main_steps = counted
            return j
        job = self.assert_cancel_leaves_nothing(
            PLUME_OT_surfaces_build, job, lambda p: p.label == "density map image" and p.done >= 3)
        self.assertEqual(job.progress().label, "density map image")
        self.assertGreaterEqual(len(job.main_steps_seen), 3)

    def test_2_toon_cancelled(self):
        from plume.operators.toon import PLUME_OT_toon_build, ToonJob
        self.assert_cancel_leaves_nothing(PLUME_OT_toon_build, ToonJob, 2)

    def test_3_cancelled_before_run(self):
        """Cancelled at the first progress report (end of prepare()): nothing is computed."""
        from plume.operators.toon import PLUME_OT_toon_build, ToonJob
        job = self.assert_cancel_leaves_nothing(PLUME_OT_toon_build, ToonJob, 0)
        self.assertEqual(job.progress().done, 0)

    def test_4_export_mesh_cancelled(self):
        from plume.operators.surface_edits import ExportMeshJob, PLUME_OT_surfaces_export_mesh
        self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})
        self.assert_cancel_leaves_nothing(PLUME_OT_surfaces_export_mesh,
                                          lambda: ExportMeshJob(1), 1)
        self.assertEqual(bpy.ops.plume.surfaces_export_mesh(level=1), {'FINISHED'})

    def test_5_jobs_complete_after_cancels(self):
        """The same operators finish normally afterwards, and a rebuild replaces the files."""
        for _ in range(2):
            self.assertEqual(bpy.ops.plume.toon_build(), {'FINISHED'})
        files = os.listdir(os.path.join(self.tmp, "Domain"))
        self.assertEqual(len([n for n in files if n.startswith("toon_")]), FRAMES)
        self.assertFalse([n for n in files if n.startswith(".plume_job_")], files)

    # ------------------------------------------------------------------ one job per domain
    def test_6_busy_domain_refuses_a_second_job(self):
        from plume.jobs import JobRunner, registry

        class Holder(JobRunner):  # a running job that holds the domain, doing nothing
            title = "Build Surfaces"

            def prepare(self, context):
                pass

            def job_spec(self):
                return {}

            def finish(self, context):
                return 'INFO', ""
        holder = Holder()
        registry.claim(holder, [("domain", "Domain")])
        try:
            before = self.state()
            for op in (bpy.ops.plume.toon_build, bpy.ops.plume.bake, bpy.ops.plume.cache_free):
                with self.assertRaises(RuntimeError) as cm:
                    op()
                self.assertRegex(str(cm.exception), "Build Surfaces|busy")
            self.assertEqual(self.state(), before)
        finally:
            registry.release(holder)

    # ------------------------------------------------------------------ file load
    def test_7_loading_a_file_aborts_a_running_job(self):
        """A job's child running when another file is loaded: the persistent load_pre handler
        kills it, reaps it and removes its staging folder and job files."""
        from plume.jobs import registry
        from plume.jobs.process import JobProcess
        from plume.operators.toon import ToonJob
        before = tree_listing(self.tmp)
        job = ToonJob()
        job.prepare(bpy.context)
        JobProcess(job).start()
        t0 = time.perf_counter()
        while job.progress().done < 3 and time.perf_counter() - t0 < 30:
            job.child.poll()
            time.sleep(0.01)
        self.assertFalse(job.child.finished, "the toon build ended before the file load")
        path = os.path.join(self.tmp, "other.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
        bpy.ops.wm.open_mainfile(filepath=path)
        try:
            self.assertTrue(job.aborted and job.child.finished and job.child.killed)
            self.assertFalse(pid_alive(job.child.pid), "the job's child outlived the file load")
            self.assertIsNone(job.staging.path)
            self.assertEqual(registry.running(), [])
            os.remove(path)
            self.assertEqual(tree_listing(self.tmp), before)
        finally:
            type(self).dom = bpy.data.objects["Domain"]

    def test_12_no_plume_thread_in_blender(self):
        """A job's work runs in its child: while one runs, Blender's process has no Python
        thread of Plume (Blender reads the GIL holder's thread state without the GIL, so one
        broke its heap: the windowed UI test crashed in about 1 run in 4 before), and Plume
        registers no undo/redo handler to park one."""
        import threading
        from plume.jobs.process import JobProcess
        from plume.operators.toon import ToonJob
        for name in ("undo_pre", "redo_pre", "undo_post", "redo_post"):
            self.assertEqual([h for h in getattr(bpy.app.handlers, name)
                              if "plume" in (h.__module__ or "")], [], name)
        job = ToonJob()
        job.prepare(bpy.context)
        JobProcess(job).start()
        try:
            job.child.poll()
            self.assertNotEqual(job.child.pid, os.getpid())
            self.assertTrue(pid_alive(job.child.pid))
            self.assertEqual([t.name for t in threading.enumerate()
                              if t is not threading.main_thread()], [])
        finally:
            from plume.jobs import registry
            registry.abort(job)
        self.assertFalse(pid_alive(job.child.pid))

    def test_11_exit_with_a_running_child(self):
        """The process ends while a bake's child runs, nobody cancelling it (jobs_exit.py): the
        child is killed with it. Exit code 0, no abort, the child gone, and the bake stopped
        with whole frames, not run to its end."""
        import json
        import re
        cache = temp_dir("plume_exit_")
        script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "jobs_exit.py")
        if os.path.basename(bpy.app.binary_path or "").startswith("blender"):
            cmd = [bpy.app.binary_path, "-b", "--factory-startup", "--python", script]
        else:  # the bpy module: its own Python
            cmd = [sys.executable, script]
        proc = subprocess.run(cmd + ["--", cache], capture_output=True, text=True, timeout=300)
        out = proc.stdout + proc.stderr
        print("  " + next((line for line in out.splitlines() if "exiting" in line), "?"))
        self.assertEqual(proc.returncode, 0, out[-3000:])
        m = re.search(r"exiting with the child \(pid (\d+)\) at frame", out)
        self.assertIsNotNone(m, out[-3000:])
        self.assertNotRegex(out, r"terminate called|Traceback")
        t0 = time.perf_counter()  # the kernel's death signal may take a moment to be reaped
        while pid_alive(int(m.group(1))) and time.perf_counter() - t0 < 5:
            time.sleep(0.05)
        self.assertFalse(pid_alive(int(m.group(1))), "the bake's child outlived Blender")
        folder = os.path.join(cache, "Domain")
        with open(os.path.join(folder, "manifest.json")) as f:
            last = json.load(f)["last_complete_frame"]
        self.assertLess(last, 200)
        self.assertEqual(len([n for n in os.listdir(folder) if n.endswith(".vdb")]), last)
        self.assertEqual([n for n in os.listdir(folder) if n.startswith(".plume_job_")], [])
        rmtree(cache)

    # ------------------------------------------------------------------ staging
    def test_8_staging_commit_discard_sweep(self):
        from plume.jobs import Staging
        folder = os.path.join(self.tmp, "staging_test")
        old = os.path.join(folder, "a_old.bin")
        os.makedirs(folder)
        for name, text in (("a_old.bin", "old"), ("b.bin", "old b")):
            with open(os.path.join(folder, name), "w") as f:
                f.write(text)
        s = Staging(folder)
        staged = s.create()
        for rel in ("b.bin", os.path.join("sub", "c.bin"), "d.bin.tmp"):
            os.makedirs(os.path.dirname(os.path.join(staged, rel)), exist_ok=True)
            with open(os.path.join(staged, rel), "w") as f:
                f.write("new")
        self.assertEqual(s.final_path(os.path.join(staged, "b.bin")),
                         os.path.join(folder, "b.bin"))
        s.commit(replaced=[old, os.path.join(folder, "b.bin")])
        self.assertEqual(tree_listing(folder), ["b.bin", "sub", os.path.join("sub", "c.bin")])
        with open(os.path.join(folder, "b.bin")) as f:
            self.assertEqual(f.read(), "new")
        # Discard: the folder is as it was; a made cache folder goes too.
        s = Staging(os.path.join(folder, "new_cache"))
        with open(os.path.join(s.create(), "x.bin"), "w") as f:
            f.write("x")
        s.discard()
        self.assertFalse(os.path.exists(os.path.join(folder, "new_cache")))
        # A killed Blender's staging folder is removed by the next job in the folder.
        dead = subprocess.Popen([sys.executable, "-c", "pass"])
        dead.wait()
        os.makedirs(os.path.join(folder, f".plume_job_{dead.pid}_deadbeef", "x"))
        s = Staging(folder)
        s.create()
        s.discard()
        self.assertEqual(tree_listing(folder), ["b.bin", "sub", os.path.join("sub", "c.bin")])
        rmtree(folder)

    # ------------------------------------------------------------------ a long job says so
    def test_9_long_build_says_how_long_first(self):
        """Headless, a job forecast above LONG_JOB_S prints "<title>: <what>, about N s" before
        it starts (reports only appear when an operator ends); a short one prints nothing. The
        forecast counts the bake's streaklines (what the panel said the bake would trace) and
        frames."""
        import contextlib
        import io
        from plume import _native, streak_count
        from plume import surfaces_forecast as sf
        from plume.jobs import operator as job_operator
        from plume.snapshot import cache_folder_of
        from plume import cache
        folder = cache_folder_of(self.dom)
        lines, particles, frames = sf.shot_size(_native, folder, cache.read_manifest(folder))
        self.assertEqual(lines, streak_count.count(_native, bpy.context.scene, self.dom)[0])
        self.assertEqual(frames, FRAMES)
        seconds = sf.seconds(lines, particles, frames)
        self.assertLess(seconds, job_operator.LONG_JOB_S)  # a small scene: no word
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})
        self.assertNotIn("about", out.getvalue())
        long_job_s, job_operator.LONG_JOB_S = job_operator.LONG_JOB_S, 0.0
        out = io.StringIO()
        try:
            with contextlib.redirect_stdout(out):
                self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})
        finally:
            job_operator.LONG_JOB_S = long_job_s
        first = out.getvalue().splitlines()[0]
        self.assertEqual(first, f"Plume: Build Surfaces: {lines:,} streaklines x {frames} "
                                f"frames, about {seconds:.0f} s")
        print(f"  forecast {seconds:.2f} s for {lines} streaklines x {frames} frames")

    def test_10_build_beyond_free_memory_is_refused(self):
        """A build that would not fit in free memory is refused before anything is computed or
        written, naming the streaklines and the memory they need (free memory is faked small:
        the check reads it when the button is pressed)."""
        from plume import _native, cache, point_sources
        from plume import surfaces_forecast as sf
        from plume.snapshot import cache_folder_of
        folder = cache_folder_of(self.dom)
        lines, particles, frames = sf.shot_size(_native, folder, cache.read_manifest(folder))
        need = sf.memory_bytes(lines, particles, frames)
        available = point_sources.available_bytes
        point_sources.available_bytes = lambda: int(need) - 1
        try:
            assert_reports_error(self, bpy.ops.plume.surfaces_build,
                                 rf"{lines:,} streaklines over {frames} frames need about "
                                 r"[0-9.]+ GB .* than the [0-9.]+ GB of memory free",
                                 self.state)
        finally:
            point_sources.available_bytes = available
        self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})  # enough again


if __name__ == "__main__":
    run(JobsTest)

"""One writer per cache folder (jobs/folder_lock.py): a second Blender baking into the same cache
folder is refused before anything is written, with a message naming who holds it; a stale lock
(killed holder, dead pid) is taken over; a lock from another host is honoured while it is
refreshed and taken over after; the lock goes when the job ends; concurrent takers of a stale
lock never both win.

The second Blender is a real one (cache_lock_child.py in ``blender -b --factory-startup``, or the
bpy module's Python), synchronized over its stdin/stdout, with no sleeps.

Run: blender_tests/run.py --blender 3.4 blender_tests/test_cache_lock.py
"""

import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import (add_domain, add_sphere_source, reset_scene, rmtree, run,  # noqa: E402
                     select_only, skip_machine_lacks, temp_dir, tree_listing)

HERE = os.path.dirname(os.path.abspath(__file__))
CHILD = os.path.join(HERE, "cache_lock_child.py")
#: Seconds a child may take to start Blender and reach the line the test waits for.
CHILD_TIMEOUT_S = 300


def child_command(mode, arg):
    """The second Blender: the same kind as this one (executable or bpy module)."""
    binary = bpy.app.binary_path
    if binary and os.path.basename(binary).startswith("blender"):
        return [binary, "-b", "--factory-startup", "--python-exit-code", "1", "--python", CHILD,
                "--", mode, arg]
    boot = ("import runpy, sys, bpy; sys.argv = sys.argv[1:]; "
            "runpy.run_path(sys.argv[0], run_name='__main__')")
    return [sys.executable, "-c", boot, CHILD, "--", mode, arg]


class Child:
    """A running cache_lock_child.py; lines read from its stdout."""

    def __init__(self, mode, arg):
        self.proc = subprocess.Popen(child_command(mode, arg), stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.log = []

    def wait_for(self, prefix):
        """The rest of the first stdout line starting with `prefix` (the log when it ends)."""
        timer = threading.Timer(CHILD_TIMEOUT_S, self.proc.kill)
        timer.start()
        try:
            for line in self.proc.stdout:
                self.log.append(line)
                if line.startswith(prefix):
                    return line[len(prefix):].strip()
        finally:
            timer.cancel()
        raise AssertionError(f"the child ended without {prefix!r}:\n{''.join(self.log)}")

    def finish(self):
        """Closes its stdin (it goes on) and waits for it; its exit code."""
        self.proc.stdin.close()
        rest = self.proc.stdout.read()
        self.log.append(rest)
        return self.proc.wait(CHILD_TIMEOUT_S)

    def kill(self):
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait(CHILD_TIMEOUT_S)
        self.proc.stdin.close()
        self.proc.stdout.close()


def folder_lock():
    from plume.jobs import folder_lock as fl
    return fl


class CacheLockTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_lock_")
        self.cache = os.path.join(self.tmp, "cache")
        self.folder = os.path.join(self.cache, "Domain")
        add_sphere_source()
        self.domain = add_domain(resolution=16, frame_end=4, cache_directory=self.cache + "/")
        select_only(self.domain)
        self.children = []

    def tearDown(self):
        for c in self.children:
            if c.proc.poll() is None:
                c.kill()
        rmtree(self.tmp)

    def child(self, mode, arg):
        c = Child(mode, arg)
        self.children.append(c)
        return c

    def lock_file(self):
        return os.path.join(self.folder, ".plume.lock")

    def assert_refused(self, *words):
        """plume.bake raises naming every word; no file or object changed."""
        files, objects = tree_listing(self.tmp), len(bpy.data.objects)
        with self.assertRaises(RuntimeError) as cm:
            bpy.ops.plume.bake()
        msg = str(cm.exception)
        for w in words:
            self.assertIn(str(w), msg)
        self.assertEqual(tree_listing(self.tmp), files, "files changed")
        self.assertEqual(len(bpy.data.objects), objects, "objects changed")
        return msg

    def assert_baked(self, frames=4):
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        names = os.listdir(self.folder)
        self.assertEqual(len([n for n in names if n.endswith(".vdb")]), frames, names)
        self.assertNotIn(".plume.lock", names, "the lock outlived the bake")
        self.assertFalse([n for n in names if n.endswith(".tmp")], names)

    # ------------------------------------------------------------------ a live second Blender
    def test_bake_refused_while_another_blender_bakes(self):
        other = self.child("bake", self.cache)
        pid = int(other.wait_for("BAKING "))  # it holds the lock, paused after frame 1
        with open(self.lock_file()) as f:
            record = json.load(f)
        self.assertEqual((record["pid"], record["host"], record["job"]),
                         (pid, socket.gethostname(), "Bake"))
        msg = self.assert_refused(f"pid {pid}", f"host {socket.gethostname()}", "(Bake, since",
                                  self.folder, "wait for it")
        print("  refusal:", msg)
        with self.assertRaises(RuntimeError) as cm:  # nor may Free Bake delete its frames
            bpy.ops.plume.cache_free()
        self.assertIn(f"pid {pid}", str(cm.exception))
        self.assertEqual(other.finish(), 0, "".join(other.log))
        self.assertIn("RESULT ['FINISHED']", "".join(other.log))
        self.assertFalse(os.path.exists(self.lock_file()), "the child's bake kept its lock")
        self.assert_baked()  # now it is free; the child's bake is complete: nothing to compute

    def test_other_blender_refused_while_this_one_holds(self):
        fl = folder_lock()
        lock = fl.acquire(self.folder, "Bake")
        try:
            other = self.child("try", self.cache)
            msg = other.wait_for("REFUSED ")
            self.assertIn(f"pid {os.getpid()}", msg)
            self.assertIn(f"host {socket.gethostname()}", msg)
            self.assertEqual(other.finish(), 0)
            self.assertEqual(os.listdir(self.folder), [".plume.lock"], "the child wrote files")
        finally:
            lock.release()
        # The lock made cache/Domain (and cache/) for itself: gone with it.
        self.assertEqual(tree_listing(self.tmp), [], "release left files")
        self.assert_baked()

    def test_two_domains_sharing_a_folder_in_one_blender(self):
        fl = folder_lock()
        lock = fl.acquire(self.folder, "Build Surfaces")
        try:
            msg = self.assert_refused("this Blender", "Build Surfaces")
        finally:
            lock.release()
        print("  refusal:", msg)

    def test_every_job_writing_the_folder_is_refused(self):
        # The lock is part of the job machinery: each job on the domain's folder asks for it.
        # Build Toon Smoke needs a bake and a camera before it gets that far: bake first.
        self.assert_baked()
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        bpy.context.scene.collection.objects.link(cam)
        bpy.context.scene.camera = cam
        select_only(self.domain)
        other = self.child("hold", self.folder)
        pid = int(other.wait_for("HELD "))
        files = tree_listing(self.tmp)
        for op in (bpy.ops.plume.bake, bpy.ops.plume.cache_free, bpy.ops.plume.surfaces_build,
                   bpy.ops.plume.toon_build, bpy.ops.plume.fire_synthesize):
            with self.assertRaises(RuntimeError, msg=op.idname()) as cm:
                op()
            self.assertIn(f"pid {pid}", str(cm.exception), op.idname())
        self.assertEqual(tree_listing(self.tmp), files, "files changed")
        self.assertEqual(other.finish(), 0, "".join(other.log))

    # ------------------------------------------------------------------ stale locks
    def test_lock_of_a_killed_blender_is_taken_over(self):
        other = self.child("hold", self.folder)
        pid = int(other.wait_for("HELD "))
        self.assert_refused(f"pid {pid}")
        other.kill()  # SIGKILL: no release; the file stays, its flock goes with the process
        with open(self.lock_file()) as f:
            self.assertEqual(json.load(f)["pid"], pid)
        self.assert_baked()

    def test_lock_of_a_dead_pid_is_taken_over(self):
        gone = subprocess.Popen(["true"])
        gone.wait()  # a pid that no longer runs (and no flock: a record copied by hand)
        os.makedirs(self.folder)
        record = dict(folder_lock().own_record("Bake"), pid=gone.pid, pid_start=None)
        with open(self.lock_file(), "w") as f:
            json.dump(record, f)
        self.assert_baked()

    def test_pid_reused_by_another_process_is_stale(self):
        os.makedirs(self.folder)  # our own pid with another start time: a reused pid
        record = dict(folder_lock().own_record("Bake"), pid_start=1)
        if record.get("pid_start") is None:
            skip_machine_lacks(self, "/proc (process start times are unknown)")
        with open(self.lock_file(), "w") as f:
            json.dump(record, f)
        self.assert_baked()

    def test_lock_from_another_host(self):
        fl = folder_lock()
        os.makedirs(self.folder)
        record = dict(fl.own_record("Bake"), host="farm07.elsewhere", pid=1234)
        with open(self.lock_file(), "w") as f:
            json.dump(record, f)
        # Refreshed now: honoured, however long ago it started.
        msg = self.assert_refused("pid 1234", "host farm07.elsewhere", "(Bake, since",
                                  "min after its last sign of life", self.lock_file())
        print("  refusal:", msg)
        # Refreshed just inside the limit: still honoured.
        now = time.time()
        inside = now - fl.REMOTE_STALE_S + 120
        os.utime(self.lock_file(), (inside, inside))
        self.assert_refused("farm07.elsewhere")
        # Not refreshed for longer than the limit: its Blender is gone; taken over.
        old = now - fl.REMOTE_STALE_S - 120
        os.utime(self.lock_file(), (old, old))
        self.assert_baked()

    def test_empty_lock_file_is_stale(self):
        os.makedirs(self.folder)  # a taker killed before its record was written
        open(self.lock_file(), "w").close()
        self.assert_baked()

    # ------------------------------------------------------------------ races and release
    def test_concurrent_takers_of_a_stale_lock_one_wins(self):
        # Threads stand for processes: each acquire() opens the file itself, so flocks conflict
        # between them as between processes. 8 takers x 40 rounds, released between rounds.
        fl = folder_lock()
        gone = subprocess.Popen(["true"])
        gone.wait()
        os.makedirs(self.folder)
        for round_ in range(40):
            stale = dict(fl.own_record("Bake"), pid=gone.pid, pid_start=None)
            if round_ % 2:  # odd rounds: no lock file at all, so creators race
                with open(self.lock_file(), "w") as f:
                    json.dump(stale, f)
            barrier, won, refused = threading.Barrier(8), [], []

            def take():
                barrier.wait()
                try:
                    won.append(fl.acquire(self.folder, "Bake"))
                except fl.LockHeld as e:
                    refused.append(str(e))

            threads = [threading.Thread(target=take) for _ in range(8)]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            self.assertEqual((len(won), len(refused)), (1, 7), (round_, refused))
            with open(self.lock_file()) as f:
                self.assertEqual(json.load(f)["started"], won[0].record["started"])
            won[0].release()
            self.assertFalse(os.path.exists(self.lock_file()))
            self.assertEqual(os.listdir(self.folder), [], "temporaries left")

    def test_lock_released_when_the_bake_fails_or_is_cancelled(self):
        from helpers import run_cancelled
        from plume.operators.bake import BakeJob, PLUME_OT_bake
        run_cancelled(PLUME_OT_bake, BakeJob(), after=2)
        self.assertFalse(os.path.exists(self.lock_file()), "cancelled bake kept its lock")
        self.domain.plume.domain.vorticity = -1.0  # refused in prepare(), after the lock
        self.assert_refused("Vorticity (ε) (Physics Properties › Plume › Forces)")
        self.assertFalse(os.path.exists(self.lock_file()))
        self.domain.plume.domain.vorticity = 0.0
        self.assert_baked()

    def test_lock_released_when_a_file_load_aborts_the_bake(self):
        # The bake's child running (as from a button) past frame 1; loading a file aborts it
        # (quit takes the same path: registry.abort_all). The lock is Blender's for the child's
        # whole life: a second writer is refused while the child writes.
        from plume.jobs import registry
        from plume.jobs.process import JobProcess
        from plume.operators.bake import BakeJob
        job = BakeJob()
        job.prepare(bpy.context)
        os.environ["PLUME_JOB_GATE"] = os.path.join(self.tmp, "never") + "@1"  # held at frame 1
        try:
            JobProcess(job).start()
        finally:
            del os.environ["PLUME_JOB_GATE"]
        t0 = time.perf_counter()
        while job.progress().done < 1 and time.perf_counter() - t0 < CHILD_TIMEOUT_S:
            job.child.wait(0.05)
        self.assertFalse(job.child.finished, "the bake ended before the file load")
        self.assertTrue(os.path.exists(self.lock_file()))
        with self.assertRaises(folder_lock().LockHeld):
            folder_lock().acquire(self.folder, "Bake")
        path = os.path.join(self.tmp, "other.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
        bpy.ops.wm.open_mainfile(filepath=path)
        self.assertTrue(job.aborted and job.child.finished)
        self.assertEqual(registry.running(), [])
        self.assertFalse(os.path.exists(self.lock_file()), "the aborted bake kept its lock")

    def test_refresh_notices_a_lock_taken_away(self):
        fl = folder_lock()
        lost = []
        lock = fl.acquire(self.folder, "Bake", on_lost=lambda: lost.append(1))
        try:
            self.assertTrue(lock.refresh())
            os.remove(self.lock_file())  # deleted by hand, and another writer took it
            other = fl.acquire(self.folder, "Bake")
            self.assertFalse(lock.refresh())
            self.assertEqual(lost, [1])
            lock.release()  # must not delete the other writer's lock
            self.assertTrue(os.path.exists(self.lock_file()))
            other.release()
        finally:
            lock.release()

    def test_unwritable_folder_names_the_setting(self):
        blocker = os.path.join(self.tmp, "not_a_folder")
        with open(blocker, "w") as f:
            f.write("x")
        self.domain.plume.domain.cache_directory = os.path.join(blocker, "cache") + "/"
        self.assert_refused("Cache Directory", "not_a_folder",
                            "(Physics Properties › Plume › Cache) is not writable")


if __name__ == "__main__":
    run(CacheLockTest)

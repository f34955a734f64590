"""A bake killed with SIGKILL at random instants and resumed each time ends bit-identical to a
straight bake, grid by grid (the power cut, the farm's pre-emption, the artist's `kill -9`).

A child Blender (children/bake_scene.py, the same Blender as this test: the executable, or the
bpy venv's Python) bakes a 48³ domain over 36 frames; it is killed KILLS times, each at a seeded
random instant once the cache has grown by one to three frames (a further 0-150 ms, so some
kills land inside a frame's write). After each kill the cache must be consistent: the manifest
reads, and every frame up to its last_complete_frame opens with all its grids; the temporaries
a kill leaves mid-write are removed by the next bake. A last child finishes the bake (a
resume), and this process bakes the same scene straight into another folder: every grid of
every frame must be equal bit for bit.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_kill_resume.py
"""

import json
import os
import random
import signal
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import (add_domain, add_sphere_source, assert_same_frames,  # noqa: E402
                     incense_streak_scene, native, reset_scene, rmtree, run, select_only,
                     temp_dir)

HERE = os.path.dirname(os.path.abspath(__file__))
CHILD = os.path.join(HERE, "children", "bake_scene.py")
RESOLUTION, FRAMES, KILLS, SEED = 48, 36, 5, 18
GRIDS = ("density", "temperature", "velocity")
#: Seconds a child may take to start and bake its next frames before the test gives up.
CHILD_LIMIT_S = 120.0


def child_command(cache):
    """This Blender, headless, running CHILD (as run.py runs a test file)."""
    args = [cache, str(RESOLUTION), str(FRAMES)]
    if bpy.app.binary_path and os.path.basename(bpy.app.binary_path).startswith("blender"):
        return [bpy.app.binary_path, "-b", "--factory-startup", "--python", CHILD, "--", *args]
    boot = ("import runpy, sys, bpy; sys.argv = sys.argv[1:]; "
            "runpy.run_path(sys.argv[0], run_name='__main__')")
    return [sys.executable, "-c", boot, CHILD, *args]


def frame_file(cache, frame):
    return os.path.join(cache, "Domain", f"volume_{frame:04d}.vdb")


def manifest(cache):
    path = os.path.join(cache, "Domain", "manifest.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def frames_on_disk(cache):
    folder = os.path.join(cache, "Domain")
    if not os.path.isdir(folder):
        return 0
    return sum(1 for n in os.listdir(folder) if n.startswith("volume_") and n.endswith(".vdb"))


class KillResumeTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_kill_")

    def tearDown(self):
        rmtree(self.tmp)

    def kill_once(self, cache, rng):
        """Starts a child, waits until it has written 1-3 more frames and a further 0-150 ms,
        SIGKILLs it; returns the frame count on disk at the kill (None: it finished first)."""
        target = frames_on_disk(cache) + rng.randint(1, 3)
        extra = rng.uniform(0.0, 0.15)
        proc = subprocess.Popen(child_command(cache), stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        t0 = time.perf_counter()
        try:
            while frames_on_disk(cache) < target:
                if proc.poll() is not None:
                    return None
                self.assertLess(time.perf_counter() - t0, CHILD_LIMIT_S, "child bake stalled")
                time.sleep(0.01)
            time.sleep(extra)
            proc.send_signal(signal.SIGKILL)
        finally:
            proc.wait()
        return frames_on_disk(cache)

    def assert_consistent(self, cache):
        """The manifest reads and every frame it calls complete opens with every grid."""
        m = manifest(cache)
        if m is None:  # killed before the first frame was committed
            self.assertEqual(frames_on_disk(cache), 0)
            return 0
        last = m["last_complete_frame"]
        nat = native()
        for f in range(m["frame_start"], last + 1):
            for grid in GRIDS:
                nat.read_vdb_grid(frame_file(cache, f), grid)
        return last

    def test_killed_bakes_resume_bit_identical(self):
        rng = random.Random(SEED)
        killed = os.path.join(self.tmp, "killed")
        kills = []
        for _ in range(KILLS):
            on_disk = self.kill_once(killed, rng)
            if on_disk is None:
                break
            tmp = [n for n in os.listdir(os.path.join(killed, "Domain")) if n.endswith(".tmp")]
            kills.append((on_disk, self.assert_consistent(killed), len(tmp)))
        print(f"  kills (frames on disk, last complete, temporaries left): {kills}")
        self.assertGreaterEqual(len(kills), 3, "the bake finished before it could be killed")
        last = self.assert_consistent(killed)
        checkpoint = manifest(killed)["state_frame"]  # resume starts after the last checkpoint
        self.assertLessEqual(checkpoint, last)
        # The last child resumes and finishes.
        done = subprocess.run(child_command(killed), capture_output=True, text=True,
                              timeout=600)
        self.assertEqual(done.returncode, 0, done.stdout[-2000:] + done.stderr[-2000:])
        m = manifest(killed)
        self.assertEqual(m["last_complete_frame"], FRAMES)
        # Temporaries a killed child left mid-write are gone once a bake ran after it.
        left = [n for n in os.listdir(os.path.join(killed, "Domain")) if n.endswith(".tmp")]
        self.assertEqual(left, [])
        self.assertTrue(m["last_run"]["resumed"])
        self.assertEqual(m["last_run"]["computed_frames"][0], checkpoint + 1)

        straight = os.path.join(self.tmp, "straight")
        add_sphere_source()
        dom = add_domain(resolution=RESOLUTION, frame_end=FRAMES, cache_directory=straight + "/")
        select_only(dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        assert_same_frames(self, frame_file, killed, straight, range(1, FRAMES + 1), GRIDS)

    def test_next_bake_removes_a_killed_writes_temporaries(self):
        """What a kill inside a write leaves (the add-on's <name>.<pid>_<hex>.tmp, a native
        writer's <name>.tmp) is removed by the next job holding the folder's lock; Plume's own
        hidden files are not touched."""
        cache = os.path.join(self.tmp, "cache")
        add_sphere_source()
        dom = add_domain(resolution=16, frame_end=3, cache_directory=cache + "/")
        select_only(dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        folder = os.path.join(cache, "Domain")
        left = ["manifest.json.4194303_0badcafe.tmp", "volume_0004.vdb.tmp", "state.bin.tmp"]
        for name in left + [".plume_probe_keep.tmp"]:
            with open(os.path.join(folder, name), "wb") as f:
                f.write(b"half a file")
        dom.plume.domain.frame_end = 5
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        names = os.listdir(folder)
        self.assertFalse(set(left) & set(names), names)
        self.assertIn(".plume_probe_keep.tmp", names)
        self.assertEqual(manifest(cache)["last_complete_frame"], 5)

    def test_kill_between_checkpoint_and_manifest_resumes(self):
        """A kill after a checkpoint is written but before the manifest names its frame (the
        window CI's random kills found: the bake started over) leaves the manifest pointing at
        the checkpoint before, which is kept (state.prev.bin, tracer_state.prev.bin): the next
        bake resumes from it and ends equal to a straight bake, volumes and streaks. The kill is
        made exact here: every frame checkpoints, and the manifest write of frame KILL_AT fails
        as the process would have died (the bake runner runs in this process for that, as the
        job's child runs it)."""
        from plume import bake_runner, snapshot
        kill_at, frames = 5, 8
        killed = os.path.join(self.tmp, "killed")
        incense_streak_scene(killed, 16, frames, point_sources=3)
        real_write, ratio = bake_runner.cache.write_manifest, bake_runner.CHECKPOINT_COST_RATIO

        def dies_at_frame(folder, data, durable=True):
            if data.get("last_complete_frame") == kill_at:
                raise OSError("killed")
            real_write(folder, data, durable)

        bake_runner.cache.write_manifest, bake_runner.CHECKPOINT_COST_RATIO = dies_at_frame, 0.0
        try:
            runner = bake_runner.BakeRunner(snapshot.take_snapshot(bpy.context), native())
            runner.prepare()
            with self.assertRaises(OSError):
                runner.run()
        finally:
            bake_runner.cache.write_manifest, bake_runner.CHECKPOINT_COST_RATIO = real_write, ratio
        m = manifest(killed)
        self.assertEqual((m["last_complete_frame"], m["state_frame"]), (kill_at - 1, kill_at - 1))
        folder = os.path.join(killed, "Domain")
        self.assertTrue({"state.bin", "state.prev.bin", "tracer_state.bin",
                         "tracer_state.prev.bin"} <= set(os.listdir(folder)))
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        m = manifest(killed)
        self.assertTrue(m["last_run"]["resumed"])
        self.assertEqual(m["last_run"]["computed_frames"], list(range(kill_at, frames + 1)))

        reset_scene()
        straight = os.path.join(self.tmp, "straight")
        incense_streak_scene(straight, 16, frames, point_sources=3)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        assert_same_frames(self, frame_file, killed, straight, range(1, frames + 1), GRIDS)
        for f in range(1, frames + 1):
            name = os.path.join("Domain", f"streaks_{f:04d}.bin")
            with open(os.path.join(killed, name), "rb") as a, \
                    open(os.path.join(straight, name), "rb") as b:
                self.assertEqual(a.read(), b.read(), name)


if __name__ == "__main__":
    run(KillResumeTest)

"""A bake whose cache folder fills up: the frame that does not fit gives an error naming the
folder, its setting and the reason (the disk is full / the file size limit), every earlier frame
and the manifest stay as they were (last_complete_frame = the frame before), no temporary or half
file is left, and once there is room again the bake resumes and ends grid for grid identical to a
straight bake.

Two ways to run out of room, both right after frame K - 1 is complete (from the bake's own
progress report, so the next write is frame K's VDB file):
- a real full disk: a 64 MB tmpfs mounted for the test and filled up by a filler file (skipped
  where mounting is not allowed, e.g. an unprivileged CI container);
- the file size limit: RLIMIT_FSIZE lowered for the bake's child process (prlimit), whose
  writes past it fail with EFBIG (the child ignores SIGXFSZ; runs everywhere).
The bake's child waits after frame K - 1 (PLUME_JOB_GATE) until the room has run out.

Run: blender_tests/run.py --blender 3.4 blender_tests/test_disk_full.py
"""

import errno
import json
import os
import resource
import signal
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import (add_domain, add_sphere_source, assert_same_frames,  # noqa: E402
                     reset_scene, rmtree, run, select_only, skip_machine_lacks, temp_dir)

RESOLUTION = 24
FRAMES = 8
#: The first frame that does not fit.
K = 5
#: Bytes a file may grow to under the lowered RLIMIT_FSIZE: below any VDB frame of this scene.
FILE_LIMIT = 1024


def volume(folder, frame):
    return os.path.join(folder, f"volume_{frame:04d}.vdb")


def read_manifest(folder):
    with open(os.path.join(folder, "manifest.json")) as f:
        return json.load(f)


def fill_up(folder):
    """Writes a filler file into `folder` until its file system has no room left; its path."""
    path = os.path.join(folder, "filler")
    with open(path, "wb", buffering=0) as f:
        for size in (1 << 20, 1 << 12):
            block = b"\0" * size
            while True:
                try:
                    f.write(block)  # short writes go on until one fails
                except OSError as e:
                    if e.errno != errno.ENOSPC:
                        raise
                    break
    return path


def bake_running_out_at(frame_done, run_out, gate_dir):
    """plume.bake with run_out(job) called once when `frame_done` frames are complete, while
    the bake's child waits at that frame (PLUME_JOB_GATE, a file in `gate_dir`)."""
    from plume.operators.bake import BakeJob, PLUME_OT_bake
    job, fired = BakeJob(), []
    gate = os.path.join(gate_dir, "gate")

    def hook(p):
        if p.done == frame_done and not fired:
            fired.append(p.done)
            run_out(job)
            open(gate, "w").close()
    job.on_progress = hook
    saved = PLUME_OT_bake.make_runner
    PLUME_OT_bake.make_runner = lambda self, context: job
    os.environ["PLUME_JOB_GATE"] = f"{gate}@{frame_done}"
    try:
        return bpy.ops.plume.bake()
    finally:
        PLUME_OT_bake.make_runner = saved
        del os.environ["PLUME_JOB_GATE"]
        os.remove(gate) if os.path.exists(gate) else None


class DiskFullTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_full_")
        self.mount = None
        self.restore = None
        add_sphere_source()
        self.domain = add_domain(resolution=RESOLUTION, frame_end=FRAMES)
        select_only(self.domain)

    def tearDown(self):
        if self.restore is not None:
            self.restore()
        if self.mount is not None:
            bpy.ops.wm.read_homefile(use_factory_startup=True)  # the Volume's open VDB files
            if subprocess.run(["umount", self.mount], capture_output=True).returncode != 0:
                subprocess.run(["umount", "-l", self.mount])
        rmtree(self.tmp)

    def bake_into(self, cache):
        self.domain.plume.domain.cache_directory = cache + "/"
        return os.path.join(cache, "Domain")

    def straight(self):
        folder = self.bake_into(os.path.join(self.tmp, "straight"))
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        return folder

    def assert_same_grids(self, folder, straight, frames):
        assert_same_frames(self, volume, folder, straight, frames)

    def run_out_and_resume(self, cache, run_out, make_room, reason):
        """Bakes into `cache`, running out of room after frame K - 1, checks what is left,
        makes room and resumes."""
        straight = self.straight()
        folder = self.bake_into(cache)
        with self.assertRaises(RuntimeError) as cm:
            bake_running_out_at(K - 1, run_out, self.tmp)
        make_room()
        msg = str(cm.exception)
        print("  report:", msg.strip())
        for words in (reason, folder, "Cache Directory", "Physics Properties › Plume › Cache",
                      f"volume_{K:04d}.vdb", "frames finished before are kept"):
            self.assertIn(words, msg)
        m = read_manifest(folder)
        self.assertEqual(m["last_complete_frame"], K - 1)
        self.assertTrue(1 <= m["state_frame"] <= K - 1, m["state_frame"])
        names = sorted(os.listdir(folder))
        self.assertEqual([n for n in names if n.endswith(".vdb")],
                         [f"volume_{f:04d}.vdb" for f in range(1, K)], names)
        self.assertFalse([n for n in names if n.endswith(".tmp") or n.startswith(".plume")],
                         names)
        self.assert_same_grids(folder, straight, range(1, K))
        # Room again: the bake resumes from its checkpoint and ends as the straight bake did.
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        m2 = read_manifest(folder)
        self.assertTrue(m2["last_run"]["resumed"])
        self.assertEqual(m2["last_run"]["computed_frames"],
                         list(range(m["state_frame"] + 1, FRAMES + 1)))
        self.assertEqual(m2["last_complete_frame"], FRAMES)
        self.assert_same_grids(folder, straight, range(1, FRAMES + 1))

    def test_disk_full_on_a_small_tmpfs(self):
        mount = os.path.join(self.tmp, "tmpfs")
        os.makedirs(mount)
        try:
            done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64m", "tmpfs", mount],
                                  capture_output=True, text=True)
            error = done.stderr.strip() if done.returncode != 0 else None
        except OSError as e:  # no mount command
            error = str(e)
        if error is not None:
            skip_machine_lacks(self, f"the right to mount a 64 MB tmpfs (mount: {error}); CI "
                                     "runs as root, where it mounts")
        self.mount = mount
        cache = os.path.join(mount, "cache")
        filler = []
        self.run_out_and_resume(cache, lambda job: filler.append(fill_up(mount)),
                                lambda: [os.remove(p) for p in filler], "the disk is full")

    def test_file_size_limit(self):
        def limit(job):  # the bake's child: it ignores SIGXFSZ, so its writes get EFBIG
            _soft, hard = resource.prlimit(job.child.pid, resource.RLIMIT_FSIZE)
            resource.prlimit(job.child.pid, resource.RLIMIT_FSIZE, (FILE_LIMIT, hard))
        self.run_out_and_resume(os.path.join(self.tmp, "cache"), limit, lambda: None,
                                "the file size limit is reached")

    def test_python_writer_leaves_no_half_file(self):
        # files.write_bytes (manifests, .npz caches) under a full disk: OSError ENOSPC, the old
        # file intact, no temporary left; no_room() names the reason.
        from plume import files
        soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
        handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        path = os.path.join(self.tmp, "data.bin")
        files.write_bytes(path, b"old")
        resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_LIMIT, hard))
        try:
            with self.assertRaises(OSError) as cm:
                files.write_bytes(path, b"x" * (4 * FILE_LIMIT))
        finally:
            resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
            signal.signal(signal.SIGXFSZ, handler)
        self.assertEqual(cm.exception.errno, errno.EFBIG)
        self.assertEqual(files.no_room(cm.exception), "the file size limit is reached")
        with open(path, "rb") as f:
            self.assertEqual(f.read(), b"old")
        self.assertEqual(os.listdir(self.tmp), ["data.bin"])


if __name__ == "__main__":
    run(DiskFullTest)

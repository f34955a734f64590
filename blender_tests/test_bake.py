"""End-to-end smoke bake through the operators: Volume sequence, VDB grids, rising density, a
Cycles render that shows the smoke, cache_free, and resume after an interrupted bake.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_bake.py
PNG renders go to $PLUME_TEST_OUT (default /tmp/plume_test_out).
"""

import json
import math
import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import (OUT_DIR, add_cube_obstacle, add_domain, add_sphere_source,  # noqa: E402
                     assert_same_frames, assert_smoke_renders, density_com_z, native, reset_scene, rmtree, run,
                     select_only, smoke_studio, temp_dir)

RESOLUTION = 32
FRAMES = 10


def build_scene(cache_dir, frame_end=FRAMES, obstacle=True):
    add_sphere_source()
    if obstacle:
        add_cube_obstacle()
    dom = add_domain(resolution=RESOLUTION, frame_end=frame_end, cache_directory=cache_dir + "/")
    select_only(dom)
    return dom


def frame_file(cache_dir, frame, domain="Domain"):
    return os.path.join(cache_dir, domain, f"volume_{frame:04d}.vdb")


def manifest(cache_dir, domain="Domain"):
    with open(os.path.join(cache_dir, domain, "manifest.json")) as f:
        return json.load(f)


class BakeTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_bake_")

    def tearDown(self):
        rmtree(self.tmp)

    def bake(self, cache_dir, **kwargs):
        dom = build_scene(cache_dir, **kwargs)
        t0 = time.perf_counter()
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        print(f"  bake took {time.perf_counter() - t0:.2f} s")
        return dom

    def test_volume_sequence_and_grids(self):
        cache = os.path.join(self.tmp, "cache")
        dom = self.bake(cache)
        ob = bpy.data.objects.get("Domain_smoke")
        self.assertIsNotNone(ob)
        self.assertEqual(ob.type, 'VOLUME')
        self.assertEqual(dom.plume.domain.volume_object, "Domain_smoke")
        vol = ob.data
        self.assertTrue(vol.is_sequence)
        self.assertEqual((vol.frame_start, vol.frame_duration), (1, FRAMES))
        self.assertEqual(vol.sequence_mode, 'CLIP')
        self.assertEqual(bpy.path.abspath(vol.filepath), frame_file(cache, 1))
        self.assertEqual(vol.materials[0].name, "Plume Smoke")
        self.assertEqual(set(ob.users_collection), set(dom.users_collection))
        self.assertEqual((dom.display_type, dom.hide_render), ('WIRE', True))
        files = sorted(n for n in os.listdir(os.path.join(cache, "Domain")) if n.endswith(".vdb"))
        self.assertEqual(files, [f"volume_{f:04d}.vdb" for f in range(1, FRAMES + 1)])
        # Blender itself reads the sequence at frame 10.
        bpy.context.scene.frame_set(FRAMES)
        self.assertTrue(vol.grids.load(), vol.grids.error_message)
        self.assertEqual(os.path.basename(vol.grids.frame_filepath), f"volume_{FRAMES:04d}.vdb")
        self.assertIn("density", [g.name for g in vol.grids])

        nat = native()
        masses, coms = [], []
        for f in range(1, FRAMES + 1):
            path = frame_file(cache, f)
            self.assertTrue({"density", "temperature", "velocity"} <= set(nat.vdb_grid_names(path)),
                            nat.vdb_grid_names(path))
            self.assertEqual(nat.read_vdb_grid(path, "velocity")["values"].shape[-1], 3)
            mass, com = density_com_z(path)
            masses.append(mass)
            coms.append(com)
        print("  density mass per frame:", [round(m, 1) for m in masses])
        print("  centre of mass z:", [round(c, 3) for c in coms])
        self.assertGreater(masses[0], 0.0)
        self.assertGreater(masses[-1], masses[0])
        self.assertTrue(all(math.isfinite(c) for c in coms))
        # The plume rises: the centre of mass climbs, frame after frame.
        self.assertGreater(coms[4], coms[0])
        self.assertGreater(coms[-1], coms[4] + 0.05)
        self.assertGreaterEqual(sum(b > a for a, b in zip(coms, coms[1:])), FRAMES - 3)

    def test_render_shows_smoke(self):
        cache = os.path.join(self.tmp, "cache")
        self.bake(cache)
        scene = bpy.context.scene
        smoke_studio(scene, samples=16)
        scene.frame_set(FRAMES)
        out = os.path.join(OUT_DIR, f"test_bake_frame{FRAMES}_")
        assert_smoke_renders(self, scene, bpy.data.objects["Domain_smoke"], out + "smoke.png",
                             out + "empty.png")

    def test_cache_free(self):
        cache = os.path.join(self.tmp, "cache")
        dom = self.bake(cache, frame_end=3, obstacle=False)
        folder = os.path.join(cache, "Domain")
        keep = os.path.join(folder, "notes.txt")  # not a Plume file: must stay
        with open(keep, "w") as f:
            f.write("artist notes")
        n_volumes = len(bpy.data.volumes)
        self.assertEqual(bpy.ops.plume.cache_free(), {'FINISHED'})
        self.assertEqual(os.listdir(folder), ["notes.txt"])
        self.assertIsNone(bpy.data.objects.get("Domain_smoke"))
        self.assertEqual(len(bpy.data.volumes), n_volumes - 1)
        self.assertEqual(dom.plume.domain.volume_object, "")
        self.assertEqual((dom.display_type, dom.hide_render), ('TEXTURED', False))
        os.remove(keep)
        bpy.ops.plume.bake()  # bakes again after a free
        self.assertEqual(bpy.data.objects["Domain_smoke"].data.frame_duration, 3)
        self.assertEqual(bpy.ops.plume.cache_free(), {'FINISHED'})
        self.assertFalse(os.path.exists(folder))

    def test_resume_matches_straight_bake(self):
        resumed, straight = os.path.join(self.tmp, "resumed"), os.path.join(self.tmp, "straight")
        # Interrupted bake: only frames 1..5 were done.
        dom = self.bake(resumed, frame_end=5)
        m = manifest(resumed)
        self.assertEqual((m["last_complete_frame"], m["state_frame"]), (5, 5))
        mtimes = {f: os.stat(frame_file(resumed, f)).st_mtime_ns for f in range(1, 6)}
        time.sleep(0.05)
        dom.plume.domain.frame_end = FRAMES
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        m = manifest(resumed)
        self.assertEqual(m["last_run"]["computed_frames"], list(range(6, FRAMES + 1)))
        self.assertTrue(m["last_run"]["resumed"])
        self.assertEqual(m["frames_computed_total"], FRAMES)
        self.assertEqual(m["last_complete_frame"], FRAMES)
        for f, t in mtimes.items():
            self.assertEqual(os.stat(frame_file(resumed, f)).st_mtime_ns, t, f"frame {f} rewritten")
        self.assertEqual(bpy.data.objects["Domain_smoke"].data.frame_duration, FRAMES)

        # The same settings baked in one go, into another cache folder.
        dom.plume.domain.cache_directory = straight + "/"
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(manifest(straight)["last_run"]["computed_frames"],
                         list(range(1, FRAMES + 1)))
        assert_same_frames(self, frame_file, resumed, straight, (5, 6, FRAMES))

    def test_cancel_from_another_thread_then_resume(self):
        # What a job's child does (jobs/child.py: the bake on a thread of its own, SIGTERM from
        # Esc -> cancel from its main thread), here in this process.
        import threading
        from plume import _native, bake_runner, snapshot
        cache = os.path.join(self.tmp, "cache")
        build_scene(cache, frame_end=30, obstacle=False)
        done = threading.Event()
        seen = []

        def progress(p):
            seen.append(p.frames_done)
            if p.frames_done >= 2:
                done.set()

        runner = bake_runner.BakeRunner(snapshot.take_snapshot(bpy.context), _native, progress)
        runner.prepare()
        out = {}
        worker = threading.Thread(target=lambda: out.setdefault("result", runner.run()))
        worker.start()
        self.assertTrue(done.wait(120), "no progress from the worker thread")
        runner.cancel()
        worker.join(120)
        self.assertFalse(worker.is_alive())
        result = out["result"]
        self.assertTrue(result.cancelled)
        last = result.last_complete_frame
        self.assertGreaterEqual(last, 2)
        self.assertLess(last, 30)
        m = manifest(cache)
        state = m["state_frame"]
        self.assertEqual(m["last_complete_frame"], last)
        self.assertTrue(1 <= state <= last, (state, last))  # checkpoints may lag a few frames
        self.assertTrue(m["last_run"]["cancelled"])
        names = os.listdir(os.path.join(cache, "Domain"))
        self.assertFalse([n for n in names if n.endswith(".tmp")], names)
        self.assertEqual(sorted(n for n in names if n.endswith(".vdb")),
                         [f"volume_{f:04d}.vdb" for f in range(1, last + 1)])
        # Baking again resumes from the checkpoint: frames after it are recomputed (bit for bit,
        # see test_resume_matches_straight_bake), earlier ones are kept.
        bpy.data.objects["Domain"].plume.domain.frame_end = last + 2
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        m = manifest(cache)
        self.assertEqual(m["last_run"]["computed_frames"], list(range(state + 1, last + 3)))
        self.assertEqual(m["last_complete_frame"], last + 2)

    def test_rebake_same_settings_is_complete(self):
        cache = os.path.join(self.tmp, "cache")
        self.bake(cache, frame_end=3, obstacle=False)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(manifest(cache)["last_run"]["computed_frames"], [])
        # A changed setting starts over.
        bpy.data.objects["Domain"].plume.domain.vorticity = 0.5
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(manifest(cache)["last_run"]["computed_frames"], [1, 2, 3])
        self.assertFalse(manifest(cache)["last_run"]["resumed"])

    def test_mantaflow_buoyancy_units(self):
        # Buoyancy Units 'MANTAFLOW' reads α and β as Mantaflow does: its buoyancy is g α ρ / L
        # (L = the domain's longest side, 2 m here), so the bake equals a 'PHYSICAL' one with
        # α / 2 and β / 2 bit for bit, and the manifest records the physical values.
        folders = []
        for units, alpha, beta in (('MANTAFLOW', 1.0, 0.5), ('PHYSICAL', 0.5, 0.25)):
            reset_scene()
            cache = os.path.join(self.tmp, units)
            dom = build_scene(cache, frame_end=3, obstacle=False)
            d = dom.plume.domain
            d.buoyancy_units, d.alpha, d.beta = units, alpha, beta
            self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
            solver = manifest(cache)["settings"]["solver"]
            self.assertEqual((solver["alpha"], solver["beta"]), (0.5, 0.25))
            folders.append(cache)
        assert_same_frames(self, frame_file, folders[0], folders[1], range(1, 4))


if __name__ == "__main__":
    run(BakeTest)

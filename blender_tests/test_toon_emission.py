"""Toon emission follows the Source ([Cartoon Smoke] §2.1, "introducing massless marker
particles periodically at the smoke source"): a Source that moves sideways during the shot
introduces each frame's particles in its cells of that frame (within a cell of the sphere as
Blender places it on the frame), a Source keyed to Density 0 on some frames and to Emit
Particles off on others introduces none there, and a static Source is voxelized once for the
whole build, a moving one once per frame.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_toon_emission.py
"""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (add_domain, add_sphere_source, compat, native, reset_scene, rmtree,  # noqa: E402
                     run, select_only, temp_dir)

RESOLUTION = 24
FRAMES = 20
RADIUS = 0.2
EMISSION = 12
DENSITY_OFF = range(7, 11)    # frames with the Source's Density keyed to 0
PARTICLES_OFF = range(14, 16)  # frames with its Emit Particles keyed off


def key_constant(ob, path, values):
    """Keyframes ob's `path` to values {frame: value}, constant interpolation."""
    name = path.rsplit(".", 1)[1]
    for frame, value in values.items():
        setattr(ob.plume.source, name, value)
        ob.keyframe_insert(path, frame=frame)
    for fc in compat.fcurves(ob):
        if fc.data_path == path:
            for k in fc.keyframe_points:
                k.interpolation = 'CONSTANT'


def build_scene(cache_dir, moving=True, keyed=True):
    reset_scene()
    src = add_sphere_source(radius=RADIUS, location=(-0.5, 0.0, 0.4))
    s = src.plume.source
    s.velocity, s.density = (0.0, 0.0, 1.0), 2.0
    if moving:  # sideways by 1 m over the shot
        for frame, x in ((1, -0.5), (FRAMES, 0.5)):
            src.location.x = x
            src.keyframe_insert("location", index=0, frame=frame)
    if keyed:
        key_constant(src, "plume.source.density", {1: 2.0, DENSITY_OFF[0]: 0.0,
                                                   DENSITY_OFF[-1] + 1: 2.0})
        key_constant(src, "plume.source.emit_particles", {1: True, PARTICLES_OFF[0]: False,
                                                          PARTICLES_OFF[-1] + 1: True})
    dom = add_domain(resolution=RESOLUTION, frame_end=FRAMES, cache_directory=cache_dir + "/")
    t = dom.plume.domain.toon
    t.emission_count = EMISSION
    t.birth_density = 50.0  # above any density of the bake: every new particle is emitted
    scn = bpy.context.scene
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scn.collection.objects.link(cam)
    cam.location, cam.rotation_euler = (0.0, -3.2, 1.0), (np.pi / 2, 0.0, 0.0)
    scn.camera = cam
    scn.frame_start, scn.frame_end = 1, FRAMES
    select_only(dom)
    return dom, src


class ToonEmissionTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_toon_emission_")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def test_moving_keyed_source(self):
        cache = os.path.join(self.tmp, "moving")
        dom, src = build_scene(cache)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        select_only(dom)
        self.assertEqual(bpy.ops.plume.toon_build(), {'FINISHED'})
        scn = bpy.context.scene
        h = 2.0 / RESOLUTION
        # A particle in a source cell: the cell's centre lies inside the sphere or within half a
        # cell of its surface, and the particle within half a cell diagonal of that centre.
        reach = RADIUS + 0.5 * h + 0.5 * np.sqrt(3.0) * h
        last_id, emitted = -1, {}
        for f in range(1, FRAMES + 1):
            scn.frame_set(f)
            centre = np.array(src.matrix_world.translation)
            snap = native().read_toon_file(os.path.join(cache, "Domain", f"toon_{f:04d}.bin"))
            new = snap["ids"].astype(np.int64) > last_id
            if len(snap["ids"]):
                last_id = max(last_id, int(snap["ids"].max()))
            emitted[f] = int(new.sum())
            if new.any():
                dist = np.linalg.norm(snap["positions"][new] - centre, axis=1)
                self.assertLessEqual(float(dist.max()), reach,
                                     f"frame {f}: a new particle {dist.max():.3f} m from the "
                                     f"source's centre {tuple(centre.round(3))}")
        print(f"  new particles per frame: {emitted}")
        for f in range(1, FRAMES + 1):
            off = f in DENSITY_OFF or f in PARTICLES_OFF
            self.assertEqual(emitted[f], 0 if off else EMISSION, f"frame {f}")
        # Frame 1's cells are far from where the source is at the end (it moved 1 m): the last
        # frame's particles were not introduced at the first frame's place.
        scn.frame_set(1)
        first = np.array(src.matrix_world.translation)
        snap = native().read_toon_file(os.path.join(cache, "Domain", f"toon_{FRAMES:04d}.bin"))
        newest = snap["positions"][-EMISSION:]
        self.assertGreater(float(np.linalg.norm(newest - first, axis=1).min()), 0.5)

    def test_static_source_is_voxelized_once(self):
        from plume import cache as cache_mod
        from plume import toon
        from plume.snapshot import emitter_snapshots
        from plume.toon_sources import ToonSourceCells
        for moving in (False, True):
            folder = os.path.join(self.tmp, f"static_{moving}")
            dom, _src = build_scene(folder, moving=moving, keyed=False)
            self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
            m = cache_mod.read_manifest(os.path.join(folder, "Domain"))
            sources = ToonSourceCells(native(), toon.toon_grid(m),
                                      emitter_snapshots(bpy.context, dom, 1, FRAMES), 1)
            cells = [sources.cells_at(f) for f in range(1, FRAMES + 1)]
            self.assertTrue(all(c is not None and len(c) > 4 for c in cells))
            self.assertEqual(sources.voxelizations, FRAMES if moving else 1)
            same = all(c is cells[0] for c in cells)
            self.assertEqual(same, not moving)


if __name__ == "__main__":
    run(ToonEmissionTest)

"""Flame spread ([Structural Flames] §6.2): activation times follow the spread map,
through the operators: a plane is a Flame Source (plume.role_set), its Spread settings are set
and plume.flames_bake bakes; the spines_####.npz (flame ids and their sources) tell on which
frames each source's flame lives.

- Maps: a left-to-right ramp as the Activation Map (made with numpy, saved as a PNG, loaded as
  a Blender image): every flame first lives at its activation time Time Scale × (map value at
  its UV), the value computed here from the flame's base position (the plane's UV is an affine
  function of it) and the ramp's own formula, not through the add-on's sampler; no flame lives
  before its activation, and without a Duration Map it burns (attached) to the end.
- Duration Map (a bottom-to-top ramp): the attached flame ends at start + duration.
- Spread Model (eq. 7) on a tilted plane, ignited at its centre: the activation time is the
  straight distance over v_s = T_f/L (cos θ + h sin θ) (flame_placement.spread_times' reading:
  θ the elevation of the direction from the ignition point, h = H_i, v_s >= 0.05 T_f/L), so
  flames up the slope light earlier than flames as far down it.

Timing (flames.FlameBakeRunner, flame_system.cpp): the frame at index i (frame_start + i) holds
the state at time (i + 1) / fps; a source is tested for activity (start <= t < end) at the start
of every substep t_j = j·dt, and its flame appears (or its attached flame separates) at the end
of the first substep with t_j >= start (end), a time in [start + dt, start + 2 dt). The first
frame showing it therefore has a time T with start + dt <= T < start + dt + 1/fps: never before
the map's time, and at most one frame (plus one substep) after it. That window is what the
tests assert, widened by the PNG's 8-bit quantization (half a level) and 1e-6 s of rounding.

Bug found by this test (fixed in flame_placement.sample_map): the bilinear filter wrapped
across the image border, so flames within half a texel of an edge read a blend with the
opposite edge (a left-to-right ramp lit the right edge's flames half-way through the spread).

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_flame_spread.py
"""

import math
import os
import struct
import sys
import unittest
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import reset_scene, rmtree, run, select_only, temp_dir  # noqa: E402

FRAMES = 30
FPS = 24
SUBSTEPS = 2
FLAMES = 12
TIME_SCALE = 0.8        # s for an activation value of 1: the front crosses in ~19 frames
DURATION = (0.1, 0.25)  # duration value = a + b·v (v the plane's V), × Duration Scale 1 s
MAP_TEXELS = 32         # texels along the ramp
#: One 8-bit level of a PNG, halved: the most a stored value differs from the ramp's formula.
QUANT = 0.5 / 255.0
EPS = 1e-6
#: Spread model: T_f / L = 1 m/s, h = H_i, plane tilted this much about X (rising along +Y).
TILT = math.radians(40.0)
H_I = 0.5


def write_grey_png(values, path):
    """An 8-bit greyscale PNG of `values` (h, w) in [0, 1], row 0 at the bottom (Blender's
    order), written with zlib alone (independent of Blender's image code)."""
    rows = np.round(np.clip(values, 0.0, 1.0) * 255.0).astype(np.uint8)[::-1]
    raw = b"".join(b"\0" + r.tobytes() for r in rows)  # filter type 0 on every row

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    h, w = rows.shape
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def save_ramp(path, width, height, axis, a=0.0, b=1.0):
    """A greyscale PNG whose texel centres hold a + b·c, c the texel centre's coordinate in
    [0, 1] along `axis` (0: U, 1: V): bilinear sampling of it is exactly a + b·clamp(c, half a
    texel from the edges). Loaded as a file image, which is returned."""
    v, u = (np.mgrid[0:height, 0:width] + 0.5) / np.array([height, width])[:, None, None]
    write_grey_png(a + b * (u if axis == 0 else v), path)
    return bpy.data.images.load(path)


def ramp_value(c, texels, a=0.0, b=1.0):
    """The ramp's value at coordinate c (bilinear between texel centres, held at the edges)."""
    return a + b * np.clip(c, 0.5 / texels, 1.0 - 0.5 / texels)


def uv_of(ob, points):
    """UVs of world points on a flat mesh: the affine map world -> UV fitted to its corners."""
    me = ob.data
    m = np.array(ob.matrix_world)
    co = np.array([m[:3, :3] @ me.vertices[lp.vertex_index].co + m[:3, 3] for lp in me.loops])
    uv = np.array([d.uv[:] for d in me.uv_layers.active.data])
    a = np.hstack([co, np.ones((len(co), 1))])
    fit, *_ = np.linalg.lstsq(a, uv, rcond=None)
    assert np.abs(a @ fit - uv).max() < 1e-5  # the plane's UVs are affine in position
    return np.hstack([points, np.ones((len(points), 1))]) @ fit


def flame_plane(folder, rotation=(0.0, 0.0, 0.0)):
    """A 1 m plane as a Flame Source of FLAMES flames, no camera (fixed particle count)."""
    reset_scene()
    scn = bpy.context.scene
    scn.render.fps, scn.render.fps_base = FPS, 1.0
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, 0.0), rotation=rotation)
    src = bpy.context.active_object
    src.name = "Board"
    bpy.ops.plume.role_set(role='FLAME_SOURCE')
    fl = src.plume.flame
    fl.profile, fl.flames, fl.radius = 'TORCH', FLAMES, 0.02
    f = scn.plume_flames
    f.frame_start, f.frame_end, f.substeps = 1, FRAMES, SUBSTEPS
    f.cache_directory = folder + "/"
    f.voxel_size = 0.02  # coarse: the volumes are not what is tested
    select_only(src)
    return src


def lives(folder):
    """Per frame index (0 = frame_start): (sources with any flame, sources with an attached
    flame), and each source's attached flame base position (first frame it shows)."""
    from plume import flames as flames_mod
    out, bases = [], {}
    for frame in range(1, FRAMES + 1):
        sp = flames_mod.read_spines(flames_mod.spines_path(folder, frame))
        starts = np.concatenate([[0], np.cumsum(sp["counts"])[:-1]]).astype(int)
        attached = set()
        for src, sep, start in zip(sp["sources"], sp["separated"], starts):
            if not sep:
                attached.add(int(src))
                bases.setdefault(int(src), np.asarray(sp["points"][start], np.float64))
        out.append((set(int(s) for s in sp["sources"]), attached))
    return out, bases


def frame_time(index):
    """The time of the state a frame index holds (see the module docstring)."""
    return (index + 1) / FPS


class FlameSpreadTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_flame_spread_")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def assert_window(self, name, k, when, event, slack):
        """The first frame showing `event` at time `when` (s) lies in [when + dt, when + dt +
        1/fps) (module docstring), widened by `slack` s."""
        dt = 1.0 / (FPS * SUBSTEPS)
        t = frame_time(event)
        self.assertGreaterEqual(t, when + dt - slack - EPS, f"{name}: flame {k} too early")
        self.assertLess(t, when + dt + 1.0 / FPS + slack + EPS, f"{name}: flame {k} too late")

    def first_and_end(self, per_frame, k):
        """(first frame index with a flame of source k, first index after it without an
        attached one or None); asserts it stays attached in between and never comes back."""
        first = next((i for i, (anyf, _att) in enumerate(per_frame) if k in anyf), None)
        self.assertIsNotNone(first, f"source {k} never burns")
        self.assertIn(k, per_frame[first][1])  # it starts as an attached flame
        end = next((i for i in range(first, FRAMES) if k not in per_frame[i][1]), None)
        if end is not None:
            self.assertFalse(any(k in att for _a, att in per_frame[end:]),
                             f"source {k} burns again after its end")
        return first, end

    def bake_maps(self, name, duration):
        folder = os.path.join(self.tmp, name)
        src = flame_plane(folder)
        fl = src.plume.flame
        fl.spread = 'MAPS'
        fl.activation_map = save_ramp(os.path.join(self.tmp, name + "_act.png"),
                                      MAP_TEXELS, 4, axis=0)
        fl.time_scale = TIME_SCALE
        if duration:
            fl.duration_map = save_ramp(os.path.join(self.tmp, name + "_dur.png"), 4,
                                        MAP_TEXELS, axis=1, a=DURATION[0], b=DURATION[1])
            fl.duration_scale = 1.0
        for img, axis in ((fl.activation_map, 0),) + (((fl.duration_map, 1),) if duration
                                                      else ()):
            # The PNG holds the ramp to within half an 8-bit level (what QUANT allows for).
            w, h = img.size
            px = np.empty(w * h * img.channels, np.float32)
            img.pixels.foreach_get(px)
            grey = px.reshape(h, w, img.channels)[..., 0]
            c = (np.arange(w if axis == 0 else h) + 0.5) / (w if axis == 0 else h)
            want = c if axis == 0 else DURATION[0] + DURATION[1] * c
            got = grey[0] if axis == 0 else grey[:, 0]
            self.assertLess(np.abs(got - want).max(), QUANT + 1e-6)
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        per_frame, bases = lives(folder)
        self.assertEqual(sorted(bases), list(range(FLAMES)))
        uv = uv_of(src, np.array([bases[k] for k in range(FLAMES)]))
        starts = TIME_SCALE * ramp_value(uv[:, 0], MAP_TEXELS)
        ends = starts + ramp_value(uv[:, 1], MAP_TEXELS, *DURATION)
        return per_frame, starts, ends

    def test_activation_map(self):
        per_frame, starts, _ends = self.bake_maps("maps", duration=False)
        firsts = []
        for k in range(FLAMES):
            first, end = self.first_and_end(per_frame, k)
            self.assert_window("activation map", k, starts[k], first, TIME_SCALE * QUANT)
            self.assertIsNone(end, f"flame {k} stopped without a duration map")
            firsts.append(first)
        lag = np.array([frame_time(i) for i in firsts]) - starts
        print(f"  activation map: starts {starts.min():.3f}-{starts.max():.3f} s over "
              f"{len(set(firsts))} distinct first frames; first-frame time − map time "
              f"{lag.min() * FPS:.2f}-{lag.max() * FPS:.2f} frames")
        self.assertGreater(starts.max() - starts.min(), 0.5 * TIME_SCALE)  # a real spread

    def test_duration_map(self):
        per_frame, starts, ends = self.bake_maps("durations", duration=True)
        slack = QUANT * (TIME_SCALE + 1.0)
        ended = 0
        for k in range(FLAMES):
            first, end = self.first_and_end(per_frame, k)
            self.assert_window("duration map", k, starts[k], first, TIME_SCALE * QUANT)
            if end is None:  # only when its end falls past the last baked frame
                self.assertGreater(ends[k] + 1.0 / (FPS * SUBSTEPS), frame_time(FRAMES - 1)
                                   - slack - EPS)
                continue
            self.assert_window("duration map end", k, ends[k], end, slack)
            ended += 1
        print(f"  duration map: durations {(ends - starts).min():.3f}-"
              f"{(ends - starts).max():.3f} s, {ended} of {FLAMES} ended in the bake")
        self.assertGreaterEqual(ended, FLAMES - 1)

    def test_spread_model(self):
        folder = os.path.join(self.tmp, "model")
        src = flame_plane(folder, rotation=(TILT, 0.0, 0.0))
        ign = bpy.data.objects.new("Ignition", None)
        bpy.context.scene.collection.objects.link(ign)
        ign.location = (0.0, 0.0, 0.0)  # the plane's centre
        fl = src.plume.flame
        fl.spread, fl.ignition = 'MODEL', ign
        fl.spread_temperature, fl.spread_thickness = 1.0, 1.0
        f = bpy.context.scene.plume_flames
        f.height_persistent, f.height_intermittent, f.height_max = 0.2, H_I, 0.6
        select_only(src)
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        per_frame, bases = lives(folder)
        self.assertEqual(sorted(bases), list(range(FLAMES)))
        pts = np.array([bases[k] for k in range(FLAMES)])
        d = pts - np.array(ign.location)
        dist = np.linalg.norm(d, axis=1)
        elevation = np.arcsin(np.clip(d[:, 2] / np.maximum(dist, 1e-12), -1.0, 1.0))
        speed = 1.0 * np.maximum(np.cos(elevation) + H_I * np.sin(elevation), 0.05)  # eq. 7
        want = dist / speed
        firsts = np.array([self.first_and_end(per_frame, k)[0] for k in range(FLAMES)])
        for k in range(FLAMES):
            self.assert_window("spread model", k, want[k], firsts[k], 0.0)
        # Order: a flame due a frame later than another never shows first.
        seen = np.array([frame_time(i) for i in firsts])
        for a in range(FLAMES):
            for b in range(FLAMES):
                if want[b] > want[a] + 1.0 / FPS:
                    self.assertLessEqual(seen[a], seen[b])
        # The slope matters: uphill flames (elevation > 10°) are faster per metre than downhill
        # ones (< −10°): observed time/distance (the frame's lag removed, at most 1/fps + dt)
        # within a frame of eq. 7's 1 / v_s.
        far = dist > 0.15
        ratio = (seen - 1.0 / (FPS * SUBSTEPS) - 0.5 / FPS)[far] / dist[far]
        expect = (1.0 / speed)[far]
        err = np.abs(ratio - expect) * dist[far] * FPS  # in frames
        up, down = elevation[far] > math.radians(10), elevation[far] < math.radians(-10)
        print(f"  spread model: {far.sum()} flames past 15 cm; time/distance uphill "
              f"{ratio[up].mean():.3f} s/m (eq. 7 {expect[up].mean():.3f}), downhill "
              f"{ratio[down].mean():.3f} s/m (eq. 7 {expect[down].mean():.3f}); worst "
              f"{err.max():.2f} frames")
        self.assertLessEqual(err.max(), 0.5 + EPS)  # the window above, centred
        if up.any() and down.any():
            self.assertLess(ratio[up].mean(), ratio[down].mean())


if __name__ == "__main__":
    run(FlameSpreadTest)

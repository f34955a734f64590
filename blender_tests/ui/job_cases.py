"""The operators and the artist's actions of the windowed job test (job_modal.py): for each long
operator its small scene, the object it works on, a setting to change and its pipeline's Free;
for each action what the artist does while the job runs.

Scenes are small (seconds to set up) and their prerequisite bakes live in a folder shared by
every case and process (SHARED, under the run's temporary folder): the first case bakes them
(blocking), later cases find them complete and their blocking bakes return at once."""

import os
import tempfile

import bpy

from helpers import (add_domain, add_sphere_source, incense_streak_scene,  # noqa: F401
                     select_only)

#: Operator name in a case -> (bpy.ops.plume operator, its pipeline's Free operator).
OPERATORS = {"bake": ("bake", "cache_free"), "flames": ("flames_bake", "flames_free"),
             "surfaces": ("surfaces_build", "cache_free"), "toon": ("toon_build", "cache_free"),
             "graph": ("flowgraph_build", "cache_free"), "synth": ("fire_synthesize",
                                                                 "cache_free")}
#: Units of progress (frames, surfaces, density maps, per cent of the cost matrix) the job must
#: report before the action: it is well under way, and not near its end.
TRIGGER = {"bake": 3, "flames": 3, "surfaces": 2, "toon": 2, "graph": 5, "synth": 5}
#: The bake of the bake cases: 40³ over BAKE_FRAMES frames (a few seconds; the quit case's
#: resume and the straight bake it is compared with take as long each). 20, not 10: with 10
#: frames of ~0.04 s the undo+quit case's quit once came after the last frame.
BAKE_RESOLUTION, BAKE_FRAMES = 40, 20
FLAME_FRAMES = 6
SYNTH_FRAMES = 30

ACTIONS = ("esc", "load", "undo", "redo", "delete", "rename", "settings", "free", "save", "quit")


def clear_objects():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)


def bake_scene(tmp):
    """A 40³ smoke domain over BAKE_FRAMES frames and a sphere source, in a new cache folder."""
    cache = tempfile.mkdtemp(prefix="bake_", dir=tmp)
    return bake_scene_in(cache), cache


def bake_scene_in(cache):
    dom = add_domain(resolution=BAKE_RESOLUTION, frame_end=BAKE_FRAMES,
                     cache_directory=cache + "/")
    add_sphere_source()
    return dom


def flame_scene(tmp):
    """test_flames.py's candle (a wick as the Flame Source) over FLAME_FRAMES frames, in a new
    cache folder."""
    cache = tempfile.mkdtemp(prefix="flames_", dir=tmp)
    bpy.ops.mesh.primitive_cylinder_add(radius=0.002, depth=0.01, location=(0, 0, 0.005))
    src = bpy.context.view_layer.objects.active
    src.name = "Candle"
    bpy.ops.plume.role_set(role='FLAME_SOURCE')
    src.plume.flame.profile, src.plume.flame.flames = 'CANDLE', 1
    src.plume.flame.radius = 0.006
    f = bpy.context.scene.plume_flames
    f.frame_start, f.frame_end = 1, FLAME_FRAMES
    f.cache_directory = cache + "/"
    f.height_persistent, f.height_intermittent, f.height_max = 0.03, 0.05, 0.08
    f.voxel_size = 0.002  # test_flames.py: 0.001 (0.5 s a frame here)
    return src, cache


def streak_scene(shared, operator):
    """The small streak scene, baked blocking: 24³ over 60 frames for the toon smoke (40 frames a
    second), with 3 point sources a cell over 30 frames for Build Surfaces (a few seconds)."""
    cache = os.path.join(shared, "streaks_" + operator)
    dom = (incense_streak_scene(cache, 24, 60) if operator == "toon"
           else incense_streak_scene(cache, 24, 30, point_sources=3))
    assert bpy.ops.plume.bake() == {'FINISHED'}
    return dom, cache


def fire_scene(shared, graph):
    """test_flowgraph_fire.py's two fire states (32³, 40 frames, Record Pathlines) baked
    blocking, both selected, Windy active; with the flow graph built (blocking) when `graph`
    is False (the synthesis cases need it)."""
    from test_flowgraph_fire import fire_state, select
    cache = os.path.join(shared, "fire")
    src = add_sphere_source(radius=0.2, location=(0.0, 0.0, 0.3), name="Burner")
    src.plume.source.fuel, src.plume.source.density = 1.0, 0.0
    calm = fire_state("Calm", cache)
    windy = fire_state("Windy", cache, wind=(1.0, 0.0, 0.0))
    for dom in (calm, windy):
        # 4 node steps a frame (test_flowgraph_fire.py: 2): twice the nodes, four times the cost
        # matrix, so Build Flow Graph runs long enough to be acted on on a quiet machine too (the
        # progress gate of job_modal.py cannot hold its one native call).
        dom.plume.domain.pathline_nodes_per_frame = 4
        select_only(dom)
        assert bpy.ops.plume.bake() == {'FINISHED'}
    select([calm, windy], windy)
    g = windy.plume.domain.flowgraph
    g.block_size = 8 if not graph else 1  # B = 1: a cost matrix that takes seconds
    if not graph:
        if not os.path.isfile(os.path.join(cache, "Windy", "flowgraph.npz")):
            assert bpy.ops.plume.flowgraph_build() == {'FINISHED'}
        g.frame_start, g.frame_end = 1, SYNTH_FRAMES
        g.use_force_fields, g.point_preview = False, False
    return windy, os.path.join(cache, "Windy")


def set_up(operator, tmp, shared):
    """The case's scene (objects cleared first): (the object the job works on, its cache
    folder), that object selected and active."""
    clear_objects()
    if operator == "bake":
        ob, cache = bake_scene(tmp)
    elif operator == "flames":
        ob, cache = flame_scene(tmp)
    elif operator in ("surfaces", "toon"):
        ob, cache = streak_scene(shared, operator)
    else:
        ob, cache = fire_scene(shared, graph=operator == "graph")
    if operator != "graph":
        select_only(ob)
    return ob, cache


def change_settings(operator, ob):
    """The artist changes the job's main settings while it runs (the job keeps the snapshot it
    took when it started)."""
    if operator == "bake":
        ob.plume.domain.resolution = 48
    elif operator == "flames":
        f = bpy.context.scene.plume_flames
        f.frame_end, f.voxel_size, f.light_unit = FLAME_FRAMES // 2, 0.003, 2.0 * f.light_unit
    elif operator == "surfaces":
        ob.plume.domain.streak_threshold = 0.3
    elif operator == "toon":
        ob.plume.domain.toon.birth_density = 0.05
    else:
        g = ob.plume.domain.flowgraph
        g.block_size, g.frame_end = 16, SYNTH_FRAMES // 2


def leftovers(cache):
    """Files that must never stay in a cache folder once a job has ended (and did not crash):
    staging folders, job files (jobs/) and unfinished writes."""
    out = []
    for root, dirs, files in os.walk(cache):
        out += [os.path.join(root, n) for n in dirs if n.startswith(".plume_job_") or n == "jobs"]
        out += [os.path.join(root, n) for n in files if n.endswith(".tmp")]
    return out

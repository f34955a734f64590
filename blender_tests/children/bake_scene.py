"""A child Blender that bakes one fixed scene, to be killed (test_kill_resume.py).

    blender -b --factory-startup --python bake_scene.py -- CACHE RESOLUTION FRAMES
    <bpy venv>/python -c "import bpy, runpy, sys; ..." bake_scene.py CACHE RESOLUTION FRAMES

Every run builds the same scene (the sphere source of test_bake.py, no obstacle) and presses
Bake: the first run starts the cache, later ones resume it from its last checkpoint."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import bpy  # noqa: E402

from helpers import add_domain, add_sphere_source, reset_scene, select_only  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
cache, resolution, frames = args[0], int(args[1]), int(args[2])
reset_scene()
add_sphere_source()
dom = add_domain(resolution=resolution, frame_end=frames, cache_directory=cache + "/")
select_only(dom)
print("child bake:", bpy.ops.plume.bake(), flush=True)

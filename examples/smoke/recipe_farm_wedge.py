"""The smoke manual's "Recipe: a wedge on the farm", steps 1-5 (step 6, Submit, is the artist's
click: `blender_tests/test_farm.py` presses it on the single-node cluster and checks the
variants and their contact sheet; `bash .ci/screenshots` saves the panel's picture). See
examples/recipe_kit.py."""

import math
import os

import bpy

from recipe_kit import Shot, new_file, press, sphere_domain

RESOLUTION, FRAME_END = 32, 40
WEDGE = "turbulence = 0, 2, 6"
CAMERA_LOCATION = (0.0, -4.0, 1.0)


def steps(folder):
    """Yields the recipe's Shot; returns the domain. `folder` stands for the shared storage:
    the shot is saved in it and the Farm Folder is its farm/."""
    yield from new_file()                                         # 1. File › New › General
    domain = sphere_domain("//plume_cache/")                      # 2. the puff's scene,
    d = domain.plume.domain                                       #    small: a wedge is a
    d.resolution, d.frame_end = RESOLUTION, FRAME_END             #    quick look at choices
    domain.hide_render = True                                     #    its box hidden (Renders)
    scene = bpy.context.scene
    scene.frame_end = FRAME_END
    scene.camera.location = CAMERA_LOCATION                       # 3. the camera, and
    scene.camera.rotation_euler = (math.radians(90.0), 0.0, 0.0)  #    Output › Resolution % 25
    scene.render.resolution_percentage = 25
    scene.render.engine = 'CYCLES'                                #    Cycles, 16 samples, no
    scene.cycles.samples, scene.cycles.use_denoising = 16, False  #    denoiser, a dark world
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.02, 0.02,
                                                                               0.025, 1.0)
    os.makedirs(folder, exist_ok=True)                            # 4. File › Save As, on the
    press(bpy.ops.wm.save_as_mainfile,                            #    shared storage
          filepath=os.path.join(folder, "wedge_shot.blend"))
    farm = scene.plume_farm                                       # 5. Scene › Plume Farm
    farm.folder = os.path.join(folder, "farm") + os.sep
    farm.job, farm.wedge_domain = 'WEDGE', domain
    farm.wedge_settings, farm.wedge_frame = WEDGE, FRAME_END
    yield Shot("ui_farm.png", tab='SCENE', open=("SCENE_PT_plume_farm",))
    return domain

"""The manuals' recipes as code, so that a recipe, its test and its screenshots cannot drift.

Each `examples/<pipeline>/recipe_<name>.py` has `steps(cache_dir)`: a generator that performs the
recipe's numbered steps, in the manual's order, through the operators an artist clicks and with
the values the manual lists, and yields a `Shot` wherever the manual shows a panel. Its Blender
test (`blender_tests/test_recipe_<name>.py`) runs the steps to the end with `run()` and checks
the picture the recipe promises; `bash .ci/screenshots` (examples/ui_screenshots.py) runs them in
a Blender window and saves each Shot as `<pipeline>/images/<image>`. The steps stop before the
render (F12): the test renders at its own size and samples, the artist at Blender's.
"""

from typing import NamedTuple

import bpy


class Shot(NamedTuple):
    """A picture of the real UI at this point of the recipe."""
    image: str                   # file name in the recipe's images/ folder, ui_*.png
    editor: str = 'PROPERTIES'   # the editor maximized for the picture: PROPERTIES or VIEW_3D
    tab: str = 'PHYSICS'         # the Properties tab shown (ignored for VIEW_3D)
    scroll: int = 0              # pixels the editor is scrolled down, to show a lower panel
    open: tuple = ()             # panels (class names) drawn open though closed by default


def new_file():
    """Every recipe's first step, `yield from new_file()`: File › New › General, Plume enabled,
    the cube deleted. Yields None once the file is read, so that a windowed Blender can draw the
    new file's screen before the next step asks for its context (`run()` passes over it)."""
    import addon_utils
    bpy.ops.wm.read_homefile(use_factory_startup=True)
    yield None
    if not addon_utils.check("plume")[1]:
        if addon_utils.enable("plume", default_set=True) is None:
            raise RuntimeError("recipe: the Plume add-on could not be enabled")
    bpy.ops.object.select_all(action='DESELECT')
    bpy.data.objects["Cube"].select_set(True)
    bpy.ops.object.delete()


def press(op, **props):
    """Presses an operator's button; a recipe step that does not finish stops the recipe."""
    result = op(**props)
    if result != {'FINISHED'}:
        raise RuntimeError(f"recipe: {op.idname_py()} returned {result}")
    return result


def run(steps):
    """Performs a recipe's steps to the end, past its shots; returns what steps() returns."""
    while True:
        try:
            next(steps)
        except StopIteration as end:
            return end.value


def sphere_domain(cache_dir, streaks=False):
    """The smoke recipes' shared steps: a UV sphere (radius 0.25 m at z 0.35 m) made the Source
    and hidden from renders (Object Properties › Visibility › Renders off), a 2 m cube at z 1 m
    made the Domain (Resolution 40, End 60, Streak Surfaces when `streaks`). Returns the domain;
    the recipe bakes it (Bake) after its own settings."""
    press(bpy.ops.mesh.primitive_uv_sphere_add, radius=0.25, location=(0.0, 0.0, 0.35))
    press(bpy.ops.plume.role_set, role='SOURCE')
    bpy.context.view_layer.objects.active.hide_render = True
    press(bpy.ops.mesh.primitive_cube_add, size=2.0, location=(0.0, 0.0, 1.0))
    domain = bpy.context.view_layer.objects.active
    press(bpy.ops.plume.role_set, role='DOMAIN')
    d = domain.plume.domain
    d.resolution, d.frame_end, d.streaks = 40, 60, streaks
    d.cache_directory = cache_dir
    return domain


def dark_view(camera_location, camera_rotation_deg, lens):
    """The fire recipes' view: the camera placed (N › Item) with its Focal Length, a black
    world (World › Surface › Color), Render Engine Cycles."""
    import math
    scene = bpy.context.scene
    cam = scene.camera
    cam.location = camera_location
    cam.rotation_euler = tuple(math.radians(a) for a in camera_rotation_deg)
    cam.data.lens = lens
    world = scene.world.node_tree.nodes["Background"]
    world.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    scene.render.engine = 'CYCLES'


def flame_view(camera_location, camera_rotation_deg, lens, frame):
    """The flame recipes' last steps: dark_view(), the frame, then the Flames panel's Auto
    Exposure (it sets Cycles' film exposure, so Cycles comes first)."""
    dark_view(camera_location, camera_rotation_deg, lens)
    bpy.context.scene.frame_set(frame)
    press(bpy.ops.plume.flames_auto_exposure)

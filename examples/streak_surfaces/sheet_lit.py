"""Streak sheets in the paper's Emission shading and in Lit shading, side by side: the
newcomer's sheets (first_streaks.py, every setting at its default) lit by a low sun from the
left, on one frame.

    blender -b --factory-startup --python examples/streak_surfaces/sheet_lit.py -- OUT_DIR [FRAME]
    blender_tests/run.py --blender 4.5 --script examples/streak_surfaces/sheet_lit.py -- OUT_DIR

Emission glows with the sheet's colour whatever the lights; Lit takes the sun's light as a thin
translucent film, bright where the sun strikes it and glowing through where it shines from
behind, and casts a soft shadow on the floor. Writes OUT_DIR/sheet_emission.png,
OUT_DIR/sheet_lit.png and OUT_DIR/sheet_shading.png side by side; prints the render times.
"""

import math
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import first_streaks  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/sheet_lit.py -- OUT_DIR [FRAME]")


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    out_dir = os.path.abspath(argv[0])
    first_streaks.SHOWN = int(argv[1]) if len(argv) > 1 else 30
    os.makedirs(out_dir, exist_ok=True)
    dom, nets, _turn, build_s = first_streaks.shot(out_dir, "defaults", still=False)
    scene = bpy.context.scene
    sun = bpy.data.objects.new("Low Sun", bpy.data.lights.new("Low Sun", 'SUN'))
    sun.data.energy = 4.0
    sun.rotation_euler = (math.radians(70.0), 0.0, math.radians(-60.0))
    scene.collection.objects.link(sun)
    paths = []
    for shading in ('EMISSION', 'LIT'):
        dom.plume.domain.sheet_shading = shading
        scene_kit.select([dom], dom)
        scene_kit.run_op(bpy.ops.plume.surfaces_build, shading, "Build Surfaces")
        path, seconds = first_streaks.render(out_dir, "sheet_" + shading.lower(), sheets=True)
        final = os.path.join(out_dir, f"sheet_{shading.lower()}.png")
        os.replace(path, final)
        paths.append(final)
        print(f"{shading}: {len(nets)} surfaces, render {seconds:.1f} s", flush=True)
    print(scene_kit.strip(paths, os.path.join(out_dir, "sheet_shading.png")))


if __name__ == "__main__":
    main()

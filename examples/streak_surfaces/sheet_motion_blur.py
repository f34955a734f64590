"""Streak sheets under motion blur: the newcomer's sheets (first_streaks.py, every setting at its
default) rendered on one frame with Cycles' motion blur off and on.

    blender -b --factory-startup --python examples/streak_surfaces/sheet_motion_blur.py -- OUT_DIR [SHUTTER] [FRAME]
    blender_tests/run.py --blender 4.5 --script examples/streak_surfaces/sheet_motion_blur.py -- OUT_DIR

Cycles sets the scene at sub-frames across its shutter; the sheets' frame handler writes there
the blend of the two baked frames around each sub-frame, so a sheet that moves between frames
is smeared along its motion as a filmed one is. SHUTTER is in frames (default 1.0, a 360°
shutter, to make the smear easy to see; 0.5 is Blender's default), FRAME the frame rendered
(default 16, while the sheets' top still rises; by frame 60 they stand still). Writes OUT_DIR/blur_off.png,
OUT_DIR/blur_on.png and OUT_DIR/sheet_motion_blur.png side by side, and prints the render times
and how far the two differ (mean |difference| of the display pixels, lit-pixel counts).
"""

import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import first_streaks  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/sheet_motion_blur.py -- OUT_DIR [SHUTTER] [FRAME]")
LIT = 0.05  # a change of display value above which a pixel counts as blurred


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    out_dir = os.path.abspath(argv[0])
    shutter = float(argv[1]) if len(argv) > 1 else 1.0
    first_streaks.SHOWN = int(argv[2]) if len(argv) > 2 else 16
    os.makedirs(out_dir, exist_ok=True)
    dom, nets, _turn, build_s = first_streaks.shot(out_dir, "defaults", still=False)
    print(f"{len(nets)} surfaces (nets {', '.join(nets)}); Build Surfaces {build_s:.1f} s",
          flush=True)
    scene = bpy.context.scene
    scene.render.motion_blur_shutter = shutter
    paths, pixels = [], []
    for name, blur in (("blur_off", False), ("blur_on", True)):
        scene.render.use_motion_blur = blur
        path, seconds = first_streaks.render(out_dir, name, sheets=True)  # frame SHOWN
        final = os.path.join(out_dir, name + ".png")
        os.replace(path, final)
        paths.append(final)
        pixels.append(scene_kit.png_pixels(final))
        print(f"{name}: {seconds:.1f} s", flush=True)
    off, on = pixels
    diff = np.abs(on - off).max(axis=2)
    print(f"frame {first_streaks.SHOWN}, shutter {shutter:g} frames: {(diff > LIT).mean():.2%} "
          f"of the pixels changed by more than {LIT}", flush=True)
    print(scene_kit.strip(paths, os.path.join(out_dir, "sheet_motion_blur.png")))


if __name__ == "__main__":
    main()

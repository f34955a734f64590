"""Flames spreading over a board from a greyscale activation map: §6.2 of [Structural Flames].

    blender -b --factory-startup --python examples/flames/flame_spread.py -- OUT_DIR [FRAMES]

A wooden board (1.2 x 0.5 m) lies on the ground; it is a Flame Source of 48 flames (TORCH
profile, r = 2.5 cm) with Spread = Maps. Its Activation Map, made here with numpy and saved as
a PNG, is a greyscale image on the board's UVs: the distance from the left end (a little noise
in it, so the front is ragged) — value v lights the flame there at v × Time Scale seconds. A
Duration Map (also generated) burns each flame for 0.4-0.7 × Duration Scale seconds, so a band of
fire runs along the board from left to right, leaving it burnt out behind.

Writes OUT_DIR/flame_spread.blend (flames cache in OUT_DIR/plume_cache/flames), the maps
OUT_DIR/flame_spread_activation.png and _duration.png, flame_spread_####.png for a few frames
and flame_spread_strip.png (the manual's image); prints the bake time per frame, the burning
flames per frame (they rise as the front spreads, then fall as it burns out) and the render
time. Needs the Plume add-on (README).
"""

import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import flame_kit  # noqa: E402
import scene_kit  # noqa: E402

TAG = "flame_spread"
USAGE = f"usage: blender -b --factory-startup --python examples/flames/{TAG}.py -- OUT_DIR [FRAMES]"
DEFAULT_FRAMES = 60
SHOW = (0.2, 0.45, 0.7, 0.95)
MAP_SIZE = 64           # texels per side of the generated maps
BOARD = (1.2, 0.5)      # m


def save_map(values, path):
    """Saves a (h, w) array in [0, 1] (row 0 at the bottom, Blender's order) as a greyscale PNG
    and loads it as a file image. Returns the image."""
    h, w = values.shape
    img = bpy.data.images.new(os.path.basename(path), w, h)
    rgba = np.ones((h, w, 4), np.float32)
    rgba[..., :3] = np.clip(values, 0.0, 1.0)[..., None]
    img.pixels.foreach_set(rgba.ravel())
    img.filepath_raw = path
    img.file_format = 'PNG'
    img.save()
    bpy.data.images.remove(img)
    return bpy.data.images.load(path)


def spread_maps(out_dir):
    """Activation: u (distance from the left end) plus smooth noise, in [0, 1]; duration: 0.4 to
    0.7 at random."""
    rng = np.random.default_rng(7)
    v, u = np.mgrid[0:MAP_SIZE, 0:MAP_SIZE] / (MAP_SIZE - 1.0)
    coarse = rng.random((5, 5))
    # bilinear upsampling of a 5 x 5 random grid: smooth noise
    x = u * 4.0
    y = v * 4.0
    x0, y0 = np.minimum(x.astype(int), 3), np.minimum(y.astype(int), 3)
    fx, fy = x - x0, y - y0
    noise = (coarse[y0, x0] * (1 - fx) * (1 - fy) + coarse[y0, x0 + 1] * fx * (1 - fy)
             + coarse[y0 + 1, x0] * (1 - fx) * fy + coarse[y0 + 1, x0 + 1] * fx * fy)
    activation = 0.85 * u + 0.15 * noise
    duration = 0.4 + 0.3 * rng.random((MAP_SIZE, MAP_SIZE))
    return (save_map(activation, os.path.join(out_dir, TAG + "_activation.png")),
            save_map(duration, os.path.join(out_dir, TAG + "_duration.png")))


def setup(scene, frames):
    out_dir = os.path.dirname(scene.render.filepath)
    board = flame_kit.flame_source("Board", bpy.ops.mesh.primitive_plane_add, (0.0, 0.0, 0.03),
                                   'TORCH', 48, 0.025, size=1.0)
    board.scale = (BOARD[0], BOARD[1], 1.0)
    bpy.ops.object.transform_apply(scale=True)
    flame_kit.solid(board, (0.12, 0.07, 0.035), name="Wood")
    fl = board.plume.flame
    fl.spread = 'MAPS'
    fl.activation_map, fl.duration_map = spread_maps(out_dir)
    seconds = frames / (scene.render.fps / scene.render.fps_base)
    fl.time_scale = 0.75 * seconds      # the front reaches the right end at 3/4 of the shot
    fl.duration_scale = 0.6 * seconds
    flame_kit.floor(6.0)
    flame_kit.flames_settings(
        scene, frames, points=12, height_persistent=0.08, height_intermittent=0.15,
        height_max=0.25, lifespan_scale=0.25, buoyancy=0.5, kolmogorov=0.005,
        voxel_size=0.005, temperature_scale=1700.0, particles_per_pixel=6.0)
    scene_kit.camera(scene, (0.0, -2.3, 0.75), lens=35.0, target=(0.0, 0.0, 0.22))


def main():
    flame_kit.flame_example(TAG, USAGE, DEFAULT_FRAMES, setup, SHOW, samples=64)


if __name__ == "__main__":
    main()

"""The default colour image of each library profile ([Structural Flames] §5.1: "we find a
reference photograph and map the picture onto the two-dimensional profile"), no ``bpy``.

Each palette is painted from what photographs of such flames show, on the profile's side view,
and checked through today's view transforms: AgX (Blender 4.x/5.x) desaturates a colour with
much blue in it to cream, and any colour between linear brightness 1 and 4 loses half its
saturation there, so the palettes keep blue low (b/r <= 0.2) and spread the brightness: a
yellow core about twice the flame's mean (linear green/red 0.6: yellow-white where it is
hottest), an orange body, dim saturated red-orange edges and tip (green/red 0.2-0.35: hue 15-25
degrees under AgX, 20-35 under Filmic) at a third to a tenth of the core.
u across the widest diameter (x from -1 to 1, in widest radii), v from the base (s = 0) to the tip
(s = 1). Values are scene-linear RGB whose brightness is relative: the bake scales every flame so
that its power-weighted mean luminance is 1 (eq. 5-6 give the flame's brightness; the image
gives its colour and where it is brighter or darker).

- Candle: a dim blue cup at the base (the blue, hot, soot-free reaction zone around the wick), a
  bright yellow-white core (glowing soot), an orange mantle, an orange to red tip.
- Torch: yellow-white at the base where the fuel burns, orange above, a dark red tip.
- Campfire: a bright yellow-orange base, orange, deep red tongues at the tip.
"""

import numpy as np

#: Image size: the colour changes over a few tenths of the profile; 64 x 128 is smooth enough.
WIDTH, HEIGHT = 64, 128


def _ramp(s, stops):
    """Piecewise-linear colour over s from (s_k, (r, g, b)) stops, sorted by s."""
    keys = np.array([k for k, _ in stops])
    rgb = np.array([c for _, c in stops], np.float64)
    return np.stack([np.interp(s, keys, rgb[:, i]) for i in range(3)], axis=-1)


def _smoothstep(edge0, edge1, x):
    t = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _candle(x, s):
    core = _ramp(s, [(0.0, (1.5, 1.0, 0.3)), (0.55, (1.5, 0.95, 0.28)),
                     (0.8, (1.2, 0.6, 0.12)), (1.0, (0.6, 0.17, 0.03))])
    mantle = _ramp(s, [(0.0, (0.8, 0.32, 0.05)), (0.6, (0.7, 0.26, 0.04)),
                       (1.0, (0.35, 0.07, 0.01))])
    rgb = core + (mantle - core) * _smoothstep(0.35, 1.0, np.abs(x))[..., None]
    # The blue base: strongest at the bottom and outside, gone by a fifth of the height.
    blue = np.array([0.12, 0.3, 1.0]) * 0.45
    w = (1.0 - _smoothstep(0.04, 0.2, s)) * (0.55 + 0.45 * _smoothstep(0.0, 0.6, np.abs(x)))
    return rgb + (blue - rgb) * w[..., None]


def _torch(x, s):
    core = _ramp(s, [(0.0, (1.6, 0.95, 0.2)), (0.2, (1.4, 0.7, 0.1)),
                     (0.5, (1.1, 0.42, 0.045)), (0.75, (0.8, 0.24, 0.025)),
                     (1.0, (0.35, 0.07, 0.01))])
    edge = _ramp(s, [(0.0, (0.8, 0.26, 0.03)), (0.5, (0.55, 0.14, 0.015)),
                     (1.0, (0.15, 0.025, 0.005))])
    return core + (edge - core) * _smoothstep(0.4, 1.0, np.abs(x))[..., None]


def _campfire(x, s):
    core = _ramp(s, [(0.0, (1.7, 1.05, 0.24)), (0.2, (1.45, 0.75, 0.11)),
                     (0.5, (1.1, 0.44, 0.05)), (0.75, (0.8, 0.25, 0.025)),
                     (1.0, (0.4, 0.08, 0.01))])
    edge = _ramp(s, [(0.0, (0.85, 0.3, 0.04)), (0.5, (0.6, 0.16, 0.02)),
                     (1.0, (0.15, 0.025, 0.005))])
    return core + (edge - core) * _smoothstep(0.35, 1.0, np.abs(x))[..., None]


PALETTES = {'CANDLE': _candle, 'TORCH': _torch, 'CAMPFIRE': _campfire}


def palette_image(profile):
    """(HEIGHT, WIDTH, 3) float32, row 0 at the base, of library profile `profile` ('CANDLE',
    'TORCH', 'CAMPFIRE'; a custom curve gets the torch's)."""
    paint = PALETTES.get(profile, _torch)
    x = (np.arange(WIDTH) + 0.5) / WIDTH * 2.0 - 1.0
    s = (np.arange(HEIGHT) + 0.5) / HEIGHT
    xx, ss = np.meshgrid(x, s)
    return np.ascontiguousarray(paint(xx, ss), np.float32)

"""How a rendered fire reads, from the display-referred PNG Blender wrote through the scene's own
view transform (AgX in 4.x/5.x, Filmic in 3.4.1): the numbers issue 30's targets name.

- lit: pixels brighter than LIT in some channel (8-bit 13): the fire, not the black world;
- coloured: lit pixels with HSV saturation >= COLOURED (not grey, not clipped white);
- hue: the mean hue (degrees, circular mean) of the coloured pixels, weighted by their value:
  fire's body is orange-yellow, about 20-50 degrees; salmon-red reads below 18;
- white: lit pixels whose every channel is >= WHITE (8-bit 230): the core "clipped to white";
- blue: lit pixels whose blue channel exceeds red (the blue base of a candle).
No bpy here; numpy only (the tests read the PNG through helpers.image_pixels)."""

import numpy as np

LIT = 0.05
COLOURED = 0.25
WHITE = 0.9


def hsv(rgb):
    """(hue degrees, saturation, value) of display RGB in [0, 1], shape (..., 3)."""
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    mx, mn = rgb.max(axis=-1), rgb.min(axis=-1)
    d = np.where(mx > mn, mx - mn, 1.0)
    h = np.where(mx == r, (g - b) / d % 6.0, np.where(mx == g, (b - r) / d + 2.0, (r - g) / d + 4.0))
    h = np.where(mx > mn, h * 60.0, 0.0)
    s = np.where(mx > 0, (mx - mn) / np.where(mx > 0, mx, 1.0), 0.0)
    return h, s, mx


def measure(rgb):
    """dict of the look numbers of display pixels `rgb` (h, w, 3) in [0, 1]."""
    rgb = np.asarray(rgb, np.float64)[..., :3]
    h, s, v = hsv(rgb)
    lit = v > LIT
    n = int(lit.sum())
    coloured = lit & (s >= COLOURED)
    white = lit & (rgb.min(axis=-1) >= WHITE)
    blue = lit & (rgb[..., 2] > rgb[..., 0])
    if coloured.any():
        w = v[coloured]
        a = np.radians(h[coloured])
        hue = float(np.degrees(np.arctan2((w * np.sin(a)).sum(), (w * np.cos(a)).sum())) % 360.0)
        if hue > 300.0:
            hue -= 360.0
    else:
        hue = float("nan")
    return dict(lit=n, lit_share=n / lit.size, hue=hue,
                coloured_share=float(coloured.sum()) / max(n, 1),
                white_share=float(white.sum()) / max(n, 1),
                blue=int(blue.sum()), rows=np.nonzero(lit.any(axis=1))[0])


def text(m):
    return (f"lit {m['lit']} px ({m['lit_share'] * 100:.1f}%), hue {m['hue']:.1f} deg, "
            f"coloured {m['coloured_share'] * 100:.0f}%, white {m['white_share'] * 100:.1f}%, "
            f"blue {m['blue']} px")

"""Toon smoke stencils ([Cartoon Smoke] §2.2, Figure 3): circle, puffy cloud and hairy cloud
generated as white RGBA images whose alpha is the stencil's cut-out, no ``bpy``. Every image is
a pure function of its kind and size (fixed shapes, no randomness), written as an 8-bit PNG with
a small deterministic encoder, so two builds give byte-identical files.

    path = write_stencil(folder, 'PUFFY')      # <folder>/stencil_puffy.png
"""

import os
import struct
import zlib

import numpy as np

from . import files

#: Stencil kinds Plume generates (the UI's IMAGE kind uses the artist's file instead).
KINDS = ('CIRCLE', 'PUFFY', 'HAIRY')
#: Pixels per side of a generated stencil.
SIZE = 256
#: Supersamples per pixel side (anti-aliased edges, still deterministic).
SUPERSAMPLE = 4


def stencil_name(kind):
    return f"stencil_{kind.lower()}.png"


def _polar(size, supersample):
    """Radius and angle of every supersample, the stencil spanning [-0.5, 0.5]²."""
    n = size * supersample
    c = (np.arange(n, dtype=np.float64) + 0.5) / n - 0.5
    x, y = np.meshgrid(c, c)  # rows = y
    return np.hypot(x, y), np.arctan2(y, x), x, y


def _circle(r, _theta, _x, _y):
    return r <= 0.48


def _puffy(r, _theta, x, y):
    """A round core with eight lobes of alternating size around it (a cartoon cloud puff)."""
    inside = r <= 0.28
    for k in range(8):
        a = 2.0 * np.pi * k / 8.0 + 0.2
        lobe = 0.17 if k % 2 == 0 else 0.13
        d = 0.46 - lobe
        inside |= np.hypot(x - d * np.cos(a), y - d * np.sin(a)) <= lobe
    return inside


def _hairy(r, theta, _x, _y):
    """A disc fringed with thin radial hairs of varying length (Figure 3, right)."""
    hairs = 36
    phase = theta * hairs / (2.0 * np.pi)
    k = np.floor(phase)
    offset = np.abs(phase - k - 0.5)  # 0 at a hair's centre line, 0.5 between hairs
    length = 0.36 + 0.12 * (0.5 + 0.5 * np.sin(k * 2.3999632))  # golden angle: no pattern
    width = 0.5 * (1.0 - np.clip((r - 0.30) / np.maximum(length - 0.30, 1e-6), 0.0, 1.0))
    return (r <= 0.30) | ((r <= length) & (offset <= width * 0.9))


_SHAPES = {'CIRCLE': _circle, 'PUFFY': _puffy, 'HAIRY': _hairy}


def stencil_alpha(kind, size=SIZE, supersample=SUPERSAMPLE):
    """Coverage (size, size) float64 in [0, 1] of a generated stencil, rows from the top."""
    if kind not in _SHAPES:
        raise ValueError(f"stencil must be one of {', '.join(KINDS)} (got {kind!r})")
    inside = _SHAPES[kind](*_polar(size, supersample)).astype(np.float64)
    return inside.reshape(size, supersample, size, supersample).mean(axis=(1, 3))


def stencil_rgba(kind, size=SIZE):
    """White RGBA uint8 (size, size, 4) with the stencil as alpha."""
    a = np.round(stencil_alpha(kind, size) * 255.0).astype(np.uint8)
    rgba = np.full((size, size, 4), 255, dtype=np.uint8)
    rgba[..., 3] = a
    return rgba


def png_bytes(rgba):
    """An 8-bit RGBA PNG of a (h, w, 4) uint8 array (rows from the top), fixed compression."""
    h, w, _ = rgba.shape
    raw = b"".join(b"\x00" + rgba[row].tobytes() for row in range(h))  # filter 0 per row

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data
                + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def write_stencil(folder, kind, size=SIZE):
    """Writes <folder>/stencil_<kind>.png atomically (files.write_bytes); its path."""
    path = os.path.join(folder, stencil_name(kind))
    return files.write_bytes(path, png_bytes(stencil_rgba(kind, size)))

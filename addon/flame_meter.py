"""The flames' light meter (no ``bpy``): how bright the baked flames look on screen, from the
emission grid of their flames_####.vdb, and the film exposure that shows them well.

A camera ray through the flames collects ∫ ε / 4π ds of the `emission` grid (W/m³; the material's
emission per W/m³, flames_volume.EMISSION_PER_WATT, times Flame Brightness): the linear pixel
value where nothing absorbs (§5.3: real flames are "highly transparent"). The meter sums the grid
along the axis closest to the camera's view, takes the luminance of each column, and reads the
METER_PERCENTILE-th percentile of the columns holding flame (above FLAME_SHARE of the brightest):
the bright body of the flames, not their glow and not the single hottest voxel. Auto Exposure
sets the film exposure that puts that value at TARGET: measured under AgX (Blender 4.x/5.x) and
Filmic (3.4), a flame body of linear brightness 4 reads orange-yellow (hue 25-45 degrees) with
its hottest tenth turning white."""

import math

import numpy as np

#: Luminance of linear Rec.709 RGB.
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
METER_PERCENTILE = 90.0
FLAME_SHARE = 0.01
TARGET = 4.0


def column_brightness(emission, voxel_size, axis, flame_brightness=1.0):
    """Linear pixel luminance of each column of the (sx, sy, sz, 3) `emission` grid (W/m³)
    summed along `axis` (0, 1, 2), for the material's Flame Brightness."""
    lum = np.asarray(emission, np.float64) @ LUMINANCE
    return lum.sum(axis=axis) * voxel_size * flame_brightness / (4.0 * math.pi)


def flame_level(columns):
    """The METER_PERCENTILE-th percentile of the columns holding flame (0.0: no flame)."""
    columns = np.asarray(columns, np.float64).ravel()
    if columns.size == 0 or not np.isfinite(columns).all() or columns.max() <= 0.0:
        return 0.0
    lit = columns[columns > FLAME_SHARE * columns.max()]
    return float(np.percentile(lit, METER_PERCENTILE))


def view_axis(forward):
    """The grid axis (0 x, 1 y, 2 z) closest to the camera's view direction `forward`."""
    return int(np.argmax(np.abs(np.asarray(forward, np.float64))))


def exposure_stops(levels):
    """Film exposure (stops) putting the mean of the metered frames' levels at TARGET; None when
    no frame holds flame."""
    levels = [v for v in levels if v > 0.0]
    if not levels:
        return None
    return math.log2(TARGET / float(np.exp(np.mean(np.log(levels)))))

"""What compare_mantaflow.py measures of a bake, apart from the scene: the process's peak resident
memory, a cache folder's size, the frames' sanity and the density centroid's height, and the
line each bake prints. No bpy here."""

import os
import re

import numpy as np

MIB = 1024.0 * 1024.0


class CompareError(Exception):
    """A bake failed or produced no usable data."""


# --- memory -------------------------------------------------------------------------------------

def _status_kib(field):
    try:
        with open("/proc/self/status") as f:
            m = re.search(rf"^{field}:\s+(\d+)\s+kB", f.read(), re.M)
        return int(m.group(1)) if m else None
    except OSError:
        return None


def reset_peak_rss():
    """Resets VmHWM (Linux >= 4.0); returns the current RSS in KiB, or None if unsupported."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        return None
    rss, hwm = _status_kib("VmRSS"), _status_kib("VmHWM")
    if rss is None or hwm is None or hwm > rss + 1024:  # the reset did not take
        return None
    return rss


def peak_rss_since_reset():
    return _status_kib("VmHWM")


# --- caches --------------------------------------------------------------------------------------

def folder_bytes(folder, pattern=None):
    total = 0
    for root, _dirs, files in os.walk(folder):
        for name in files:
            if pattern is None or re.fullmatch(pattern, name):
                total += os.path.getsize(os.path.join(root, name))
    return total


def check_vdb_frames(kind, paths, native):
    """Every frame's VDB exists, is non-empty and has a density grid; smoke in the last one."""
    missing = [p for p in paths if not os.path.isfile(p) or os.path.getsize(p) == 0]
    if missing:
        raise CompareError(f"{kind} bake produced no data for {len(missing)} of {len(paths)} "
                           f"frames, e.g. {missing[0]}")
    for p in (paths[0], paths[-1]):
        names = native.vdb_grid_names(p)
        if "density" not in names:
            raise CompareError(f"{kind}: {p} has no 'density' grid (grids: {names})")
    grid = native.read_vdb_grid(paths[-1], "density")
    values = grid["values"]
    peak = float(values.max()) if values.size else 0.0
    if not peak > 0.0:
        raise CompareError(f"{kind}: the density of the last frame ({paths[-1]}) is empty")
    return peak


def density_centroid_z(path, native, cell_size, box_min_z=0):
    """Height above the floor (m) of the density centroid of a frame's VDB. Both caches index the
    domain's cells from its minimum corner (Mantaflow in its own index space, Plume with its
    world transform); the height of cell k's centre is (k + 0.5) Δx, Δx = `cell_size`. An
    adaptive Mantaflow domain indexes the cells of its box: `box_min_z` is the box's first
    cell (res_min of its config file)."""
    grid = native.read_vdb_grid(path, "density")
    values = grid["values"]
    total = float(values.sum(dtype="float64"))
    if not total > 0.0:
        raise CompareError(f"{path}: no density to take a centroid of")
    layers = values.sum(axis=(0, 1), dtype="float64")
    index = float((layers * np.arange(len(layers))).sum()) / total + grid["min"][2] + box_min_z
    return (index + 0.5) * cell_size


def report(name, seconds, frames, cache_bytes, vdb_bytes, rss0, peak, extra=""):
    mem = "n/a (cannot reset the peak RSS on this system)"
    if rss0 is not None and peak is not None:
        mem = f"{peak / 1024.0:.0f} MiB (+{max(0, peak - rss0) / 1024.0:.0f} MiB over the start)"
    print(f"{name}: {seconds:.2f} s for {frames} frames = {seconds / frames:.3f} s/frame; "
          f"cache {cache_bytes / MIB:.1f} MiB ({vdb_bytes / MIB:.1f} MiB VDB){extra}; "
          f"peak RSS during bake {mem}", flush=True)

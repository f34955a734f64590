"""Structural flames cache files, no ``bpy``: flames_manifest.json and spines_####.npz (the
spines, lights and the smoke's inputs of a frame), written atomically with files/, read back with
their sizes checked."""

import os
import zipfile
from dataclasses import asdict

import numpy as np

from . import files
from .flame_settings import FORMAT_VERSION, MANIFEST_NAME

def clear_folder(folder):
    """Removes the frames of an older bake (they would mix in) and its manifest."""
    for name in os.listdir(folder):
        if ((name.startswith("flames_") and name.endswith(".vdb"))
                or (name.startswith("spines_") and name.endswith(".npz"))
                or name == MANIFEST_NAME or name.endswith(".tmp")):
            os.remove(os.path.join(folder, name))


def remove_frames_above(folder, last):
    """Removes the frame files after frame `last` (what a bake killed between a frame's files
    and its manifest leaves)."""
    for name in os.listdir(folder):
        if ((name.startswith("flames_") and name.endswith(".vdb"))
                or (name.startswith("spines_") and name.endswith(".npz"))):
            try:
                frame = int(name[7:-4])
            except ValueError:
                continue
            if frame > last:
                os.remove(os.path.join(folder, name))


def write_manifest(snap, result):
    data = {"format_version": FORMAT_VERSION, "kind": "flames",
            "frame_start": snap.frame_start, "frame_end": snap.frame_end,
            "last_complete_frame": result.last_frame, "seed": snap.seed,
            "substeps": snap.substeps, "sources": [s.name for s in snap.sources],
            "settings": asdict(snap.settings[0]),
            # per baked frame: live flames and rendered particles (for scripts and the UI)
            "flames": list(result.flames), "particles": list(result.particles)}
    files.write_manifest(snap.folder, data, MANIFEST_NAME)


def read_manifest(folder):
    """The manifest dict, or None when missing or unreadable."""
    return files.read_manifest(folder, "flames", MANIFEST_NAME)


SPINE_ARRAYS = ("ids", "sources", "separated", "counts", "points", "light_ids", "light_centres",
                "light_radii", "light_energy", "light_colors")
#: What the smoke of §6.3 needs besides (flame_smoke.py); absent from caches of older versions:
#: the points' velocities (Σ counts, 3), each flame's radius r and its buoyancy lift (eq. 2).
SMOKE_ARRAYS = ("velocities", "radii", "lifts")


def buoyancy_lift(flame, params):
    """The upward acceleration of eq. 2 for a flame, m/s²: β |g| (T_p − T_0), the reading of
    evolution.h (the velocity c = β |g| (T_p − T_0) t_p grows at this rate)."""
    g = float(np.linalg.norm(params.gravity))
    return params.buoyancy * g * (flame["temperature"] - params.ambient_temperature)


def write_spines(path, flames, lights, params):
    """spines_####.npz: per flame its id, source, separated flag and point count, the points
    (Σ counts, 3) float32 base to tip and their velocities, its radius r and the lift of eq. 2
    under FlameParams `params`; per light (§5.2) its flame id, centre, radius h/3, energy
    (eq. 5 × intensity) and colour."""
    pts = [np.asarray(f["points"], np.float32).reshape(-1, 3) for f in flames]
    vel = [np.asarray(f["velocities"], np.float32).reshape(-1, 3) for f in flames]
    files.save_npz(path, ids=np.asarray([f["id"] for f in flames], np.uint32),
                   sources=np.asarray([f["source"] for f in flames], np.int32),
                   separated=np.asarray([f["separated"] for f in flames], bool),
                   counts=np.asarray([len(p) for p in pts], np.int32),
                   points=(np.concatenate(pts) if pts else np.zeros((0, 3), np.float32)),
                   velocities=(np.concatenate(vel) if vel else np.zeros((0, 3), np.float32)),
                   radii=np.asarray([f["radius"] for f in flames], np.float32),
                   lifts=np.asarray([buoyancy_lift(f, params) for f in flames], np.float32),
                   light_ids=np.asarray([li["flame_id"] for li in lights], np.uint32),
                   light_centres=np.asarray([li["centre"] for li in lights],
                                            np.float32).reshape(-1, 3),
                   light_radii=np.asarray([li["radius"] for li in lights], np.float32),
                   light_energy=np.asarray([li["energy"] for li in lights], np.float32),
                   light_colors=np.asarray([li["color"] for li in lights],
                                           np.float32).reshape(-1, 3))


def read_spines(path):
    """The arrays of a spines file (SMOKE_ARRAYS too when present); OSError or ValueError when it
    cannot be read or its sizes disagree (checked, never trusted)."""
    try:
        with np.load(path, allow_pickle=False) as data:
            d = {k: np.array(data[k]) for k in SPINE_ARRAYS}
            d.update({k: np.array(data[k]) for k in SMOKE_ARRAYS if k in data.files})
    except KeyError as e:
        raise ValueError(f"{path}: no {e} array") from None
    except zipfile.BadZipFile as e:
        raise ValueError(f"{path}: {e}") from None
    k, m = len(d["ids"]), len(d["light_ids"])
    if (any(len(d[a]) != k for a in ("sources", "separated", "counts"))
            or d["points"].shape != (int(d["counts"].sum()), 3) or np.any(d["counts"] < 0)
            or d["light_centres"].shape != (m, 3) or d["light_colors"].shape != (m, 3)
            or len(d["light_radii"]) != m or len(d["light_energy"]) != m
            or ("velocities" in d and d["velocities"].shape != d["points"].shape)
            or any(a in d and d[a].shape != (k,) for a in ("radii", "lifts"))):
        raise ValueError(f"{path}: arrays of mismatched sizes")
    return d

"""Cache folder layout of a smoke bake (DESIGN.md "Cache folder"), no ``bpy``:

    <cache_directory>/<domain name>/manifest.json
                                    volume_<frame:04d>.vdb
                                    state.bin            (checkpoint of the last complete frame)
                                    tracer_state.bin     (streak surfaces on: the tracers' checkpoint,
                                                          same frame as state.bin)
                                    state.prev.bin, tracer_state.prev.bin   (the checkpoint before,
                                                          kept until the manifest names the new one)
                                    streaks_<frame:04d>.bin   (streak surfaces on: tracers, §3.2)
                                    surface_<n>.npz, sheet_<n>_<frame:04d>.exr  (plume.surfaces_build)
                                    toon_<frame:04d>.bin, stencil_<kind>.png   (plume.toon_build)
"""

import os
import re
import uuid

from . import files
from .files import MANIFEST_NAME, manifest_path  # noqa: F401  (cache.manifest_path)
from .files.manifest import FORMAT_VERSION  # noqa: F401

STATE_NAME = "state.bin"
TRACER_STATE_NAME = "tracer_state.bin"
#: The checkpoint before the last one: a kill between writing a checkpoint and the manifest naming
#: its frame leaves the manifest pointing at this one.
STATE_PREV_NAME = "state.prev.bin"
TRACER_STATE_PREV_NAME = "tracer_state.prev.bin"
#: Pathline groups of a fire bake ([Graph Fire Synthesis] §4.2); ".partial" while recording.
PATHLINES_NAME = "pathlines.bin"
KIND = "smoke"

_VOLUME_RE = re.compile(r"^volume_(-?\d+)\.vdb$")
_STREAK_RE = re.compile(r"^streaks_(-?\d+)\.bin$")
#: Files of plume.surfaces_build (per-surface control points and density map images).
_SURFACE_RE = re.compile(r"^(surface_\d+\.npz|sheet_\d+_-?\d+\.exr)$")
#: Files of plume.toon_build (toon particles per frame, generated stencils).
_TOON_RE = re.compile(r"^(toon_-?\d+\.bin|stencil_(circle|puffy|hairy)\.png)$")


def _frame_of(name):
    """Frame number of a per-frame file (volume or streaks), else None."""
    m = _VOLUME_RE.match(name) or _STREAK_RE.match(name)
    return int(m.group(1)) if m else None


def folder_name(domain_name):
    """A domain's sub-folder name: the object name with path separators replaced."""
    name = domain_name.replace("/", "_").replace("\\", "_").replace("\0", "_")
    return "_" + name if name in (".", "..", "") else name


def cache_folder(base_directory, domain_name):
    return os.path.join(os.path.abspath(base_directory), folder_name(domain_name))


def volume_path(folder, frame):
    return os.path.join(folder, f"volume_{frame:04d}.vdb")


def streak_path(folder, frame):
    return os.path.join(folder, f"streaks_{frame:04d}.bin")


def surface_path(folder, index):
    return os.path.join(folder, f"surface_{index}.npz")


def sheet_path(folder, index, frame):
    return os.path.join(folder, f"sheet_{index}_{frame:04d}.exr")


def surface_files(folder):
    """Files of the last plume.surfaces_build in the folder."""
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return []
    return [os.path.join(folder, n) for n in names if _SURFACE_RE.match(n)]


def streak_frames(folder):
    """Frame numbers of the streaks_*.bin files present, sorted."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(int(m.group(1)) for m in map(_STREAK_RE.match, names) if m)


def state_path(folder):
    return os.path.join(folder, STATE_NAME)


def tracer_state_path(folder):
    """Checkpoint of the streak tracers, written with state.bin for the same frame."""
    return os.path.join(folder, TRACER_STATE_NAME)


def state_paths(folder):
    """The solver checkpoints a resume may load, newest first (state.bin, state.prev.bin)."""
    return [os.path.join(folder, STATE_NAME), os.path.join(folder, STATE_PREV_NAME)]


def tracer_state_paths(folder):
    """The tracer checkpoints a resume may load, newest first."""
    return [os.path.join(folder, TRACER_STATE_NAME), os.path.join(folder, TRACER_STATE_PREV_NAME)]


def keep_previous_checkpoint(folder):
    """Before a new checkpoint is written: the current one becomes the previous one (a rename of
    each existing file), so that whichever instant a kill lands at, a checkpoint of the frame the
    manifest names is on disk."""
    for paths in (state_paths(folder), tracer_state_paths(folder)):
        if os.path.isfile(paths[0]):
            os.replace(paths[0], paths[1])


def read_manifest(folder):
    """The smoke bake's manifest as a dict, or None when missing or unreadable (then the bake
    starts over)."""
    return files.read_manifest(folder, KIND)


def write_manifest(folder, data, durable=True):
    files.write_manifest(folder, data, durable=durable)


def volume_frames(folder):
    """Frame numbers of the volume_*.vdb files present, sorted."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    frames = []
    for name in names:
        m = _VOLUME_RE.match(name)
        if m:
            frames.append(int(m.group(1)))
    return sorted(frames)


def plume_files(folder):
    """Files of the folder that a bake owns: manifest.json, volume_*.vdb, streaks_*.bin, state.bin,
    tracer_state.bin, their .prev.bin, pathlines.bin(.partial), the surfaces' and toon files,
    *.tmp."""
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return []
    own = []
    for name in names:
        path = os.path.join(folder, name)
        if not os.path.isfile(path):
            continue
        if (name in (MANIFEST_NAME, STATE_NAME, TRACER_STATE_NAME, STATE_PREV_NAME,
                     TRACER_STATE_PREV_NAME, PATHLINES_NAME, PATHLINES_NAME + ".partial")
                or _frame_of(name) is not None or _SURFACE_RE.match(name)
                or _TOON_RE.match(name) or name.endswith(".tmp")):
            own.append(path)
    return own


def delete_plume_files(folder, frames_above=None):
    """Deletes the bake's files (or only volume frames > frames_above); removes the folder when it
    ends up empty. Never touches files it does not own. Returns the number of files deleted."""
    count = 0
    for path in plume_files(folder):
        if frames_above is not None:
            frame = _frame_of(os.path.basename(path))
            if frame is None or frame <= frames_above:
                continue
        try:
            os.remove(path)
            count += 1
        except FileNotFoundError:
            pass
    if frames_above is None:
        try:
            os.rmdir(folder)
        except OSError:
            pass  # not empty (artist files) or already gone
    return count


def check_writable(folder):
    """Creates `folder` if needed and writes/deletes a probe file. Returns None when writable,
    else the OS error text. Only creates directories when the whole path can be made."""
    try:
        os.makedirs(folder, exist_ok=True)
        probe = os.path.join(folder, f".plume_probe_{uuid.uuid4().hex[:8]}.tmp")
        with open(probe, "wb") as f:
            f.write(b"plume")
        os.remove(probe)
    except OSError as e:
        return e.strerror or str(e)
    return None



def pathlines_path(folder):
    return os.path.join(folder, PATHLINES_NAME)

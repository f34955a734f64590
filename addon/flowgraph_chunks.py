"""Fire synthesis in frame chunks, for the farm (no ``bpy``). [Graph Fire Synthesis] §5's walk is
one sequence, but its frames can be written by many tasks at once: each task replays the walk
and the particles from the first frame and writes only its own frames (SynthesisRunner.run's
`write`), into a chunk folder of its own inside the cache folder:

    <cache folder>/farm_synthesis/<first>-<last>/fire/fire_<frame>.vdb, points_<frame>.npz
                                                 chunk.json  (frames, key, the walk's summary)
                                                 fire/walk.npz (the chunk that ends the range)

Then one task gathers them (gather()): every frame of the range present exactly once, every
chunk made from the same settings and flow graph (the key), the files linked into the
synthesis's staging folder, so Synthesize Fire's own finish() commits them and builds the fire
Volume as after a local run. The chunk folders are removed after that commit (remove())."""

import dataclasses
import hashlib
import json
import os
import pickle
import shutil

from . import files
from .flowgraph import (FIRE_FOLDER, GRAPH_NAME, WALK_NAME, SynthesisResult, fire_path,
                        points_path)
from .settings import BakeError

CHUNKS_FOLDER = "farm_synthesis"
CHUNK_NAME = "chunk.json"


def chunks_root(cache_folder):
    return os.path.join(cache_folder, CHUNKS_FOLDER)


def chunk_folder(cache_folder, first, last):
    return os.path.join(chunks_root(cache_folder), f"{int(first)}-{int(last)}")


def settings_key(settings, cache_folder):
    """What every chunk of one synthesis shares: its settings (frame inputs included) and the
    flow graph's bytes, hashed."""
    h = hashlib.sha256(pickle.dumps(dataclasses.asdict(settings), protocol=4))
    try:
        with open(os.path.join(cache_folder, GRAPH_NAME), "rb") as f:
            h.update(f.read())
    except OSError:
        pass  # load_graph() reports the missing graph
    return h.hexdigest()


def write_record(staging, first, last, key, result):
    """chunk.json into the chunk's staging folder: its frames, the key and the walk's summary."""
    record = {"frames": [int(first), int(last)], "key": key,
              "result": dataclasses.asdict(result)}
    files.write_bytes(os.path.join(staging, CHUNK_NAME), json.dumps(record).encode("utf-8"))


def _records(cache_folder):
    root = chunks_root(cache_folder)
    try:
        names = sorted(os.listdir(root))
    except OSError:
        names = []
    out = []
    for name in names:
        path = os.path.join(root, name, CHUNK_NAME)
        try:
            with open(path, encoding="utf-8") as f:
                record = json.load(f)
            first, last = (int(v) for v in record["frames"])
        except (OSError, ValueError, KeyError, TypeError):
            continue  # a chunk folder whose task has not committed: not a chunk yet
        out.append((first, last, record, os.path.join(root, name)))
    return sorted(out, key=lambda r: r[:2])


def gather(cache_folder, staging, settings, key, owner):
    """Links every chunk's files into `staging` (the synthesis job's staging folder) and returns
    the whole walk's SynthesisResult; BakeError naming the frames missing, doubled or made from
    other settings. Nothing in the chunk folders is changed."""
    s = settings
    records = _records(cache_folder)
    stale = [os.path.basename(r[3]) for r in records if r[2].get("key") != key]
    if stale:
        raise BakeError(f"Plume: {owner}: the synthesis chunks {stale} were made from other "
                        "settings or another flow graph: submit the synthesis again")
    covered = {}
    for first, last, _record, folder in records:
        for frame in range(first, last + 1):
            covered.setdefault(frame, []).append(folder)
    missing = [f for f in range(s.frame_start, s.frame_end + 1) if f not in covered]
    doubled = [f for f, where in covered.items() if len(where) > 1]
    if doubled:
        raise BakeError(f"Plume: {owner}: the synthesis chunks hold frames {_span(doubled)} "
                        "twice (chunks of two submissions): submit the synthesis again")
    if missing:
        raise BakeError(f"Plume: {owner}: the synthesis chunks miss frames {_span(missing)}: "
                        "run the missing synthesis tasks (Scene Properties › Plume Farm › "
                        "Resubmit Missing)")
    ending = [r for r in records if r[1] == s.frame_end]
    os.makedirs(os.path.join(staging, FIRE_FOLDER), exist_ok=True)
    for first, last, _record, folder in records:
        frames = range(first, last + 1)
        names = [os.path.basename(fire_path(folder, f)) for f in frames]
        if s.point_preview:
            names += [os.path.basename(points_path(folder, f)) for f in frames]
        if first <= s.frame_end <= last:
            names.append(WALK_NAME)
        for name in names:
            src = os.path.join(folder, FIRE_FOLDER, name)
            if not os.path.isfile(src):
                raise BakeError(f"Plume: {owner}: the synthesis chunk "
                                f"{os.path.basename(folder)} has no {name}: run its task again")
            _link(src, os.path.join(staging, FIRE_FOLDER, name))
    fields = ending[0][2]["result"]
    result = SynthesisResult(**{k: v for k, v in fields.items()
                                if k in SynthesisResult.__dataclass_fields__})
    if result.unreachable_target is not None:
        result.unreachable_target = tuple(result.unreachable_target)
    return result


def remove(cache_folder):
    """The chunk folders, once their frames are committed."""
    shutil.rmtree(chunks_root(cache_folder), ignore_errors=True)


def _link(src, dst):
    """A hard link (the chunk keeps its file until the commit succeeded); a copy where the
    file system has none."""
    try:
        os.link(src, dst)
    except OSError:
        shutil.copyfile(src, dst)


def _span(frames):
    """"3-5, 9" for [3, 4, 5, 9]; "none" for []."""
    runs = []
    for f in sorted(frames):
        if runs and f == runs[-1][1] + 1:
            runs[-1][1] = f
        else:
            runs.append([f, f])
    return ", ".join(f"{a}-{b}" if b > a else str(a) for a, b in runs) or "none"

"""The manifest of a cache folder (DESIGN.md "Cache folder"): manifest.json of a domain's bake,
flames_manifest.json of a flames bake; the one reader and writer of both. Each says its "kind"
("smoke" or "flames") and "format_version"; a manifest of another kind or version reads as
missing, so the bake starts over instead of mixing in files it does not understand. So does a
damaged one (native/fuzz/fuzz_manifest.py): not JSON, nested too deep, larger than any bake
writes, or with a field the add-on reads of another type than the writer's."""

import json
import math
import os

from .atomic import write_bytes

MANIFEST_NAME = "manifest.json"
FORMAT_VERSION = 1
#: Largest manifest read, bytes: a bake of 10^5 frames writes a few megabytes at most.
MAX_MANIFEST_BYTES = 64 << 20


def _is_int(v):
    return isinstance(v, int) and not isinstance(v, bool)


def _is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _is_positive(v):
    return _is_number(v) and v > 0


def _vector3(check):
    return lambda v: isinstance(v, list) and len(v) == 3 and all(check(x) for x in v)


#: The fields the add-on reads without checking (comparisons, int(), float(), indexing), with
#: the type the writers give them; absent fields are fine (older manifests lack some).
_FIELD_CHECKS = {
    "frame_start": _is_int,
    "frame_end": _is_int,
    "last_complete_frame": _is_int,
    "state_frame": lambda v: v is None or _is_int(v),
    "frames_computed_total": _is_int,
    "settings": lambda v: isinstance(v, dict),
    "last_run": lambda v: isinstance(v, dict),
    "frame_inputs": lambda v: isinstance(v, list),
    "resolution": _vector3(lambda x: _is_int(x) and x >= 1),
    "origin": _vector3(_is_number),
    "cell_size": _is_positive,
    "cell_size_xyz": _vector3(_is_positive),
}


def manifest_path(folder, name=MANIFEST_NAME):
    return os.path.join(folder, name)


def read_manifest(folder, kind, name=MANIFEST_NAME):
    """The manifest `name` of `kind` as a dict, or None when missing, unreadable, damaged, of
    another kind or of another format version. Never raises."""
    try:
        with open(manifest_path(folder, name), "rb") as f:
            raw = f.read(MAX_MANIFEST_BYTES + 1)
        if len(raw) > MAX_MANIFEST_BYTES:
            return None
        data = json.loads(raw.decode("utf-8"))
    except (OSError, ValueError, RecursionError):  # RecursionError: "[[[[..." nested too deep
        return None
    if not isinstance(data, dict) or data.get("format_version") != FORMAT_VERSION:
        return None
    if data.get("kind") != kind:
        return None
    for field, check in _FIELD_CHECKS.items():
        if field in data and not check(data[field]):
            return None
    return data


def write_manifest(folder, data, name=MANIFEST_NAME, durable=True):
    """Writes `data` (with its "kind" and "format_version") as the folder's manifest `name`,
    atomically; fsynced when `durable` (see write_bytes)."""
    text = json.dumps(data, indent=1, sort_keys=True)
    write_bytes(manifest_path(folder, name), text.encode("utf-8"), durable)

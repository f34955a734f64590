"""The manifest of a cache folder (DESIGN.md "Cache folder"): manifest.json of a domain's bake,
flames_manifest.json of a flames bake; the one reader and writer of both. Each says its "kind"
("smoke" or "flames") and "format_version"; a manifest of another kind or version reads as
missing, so the bake starts over instead of mixing in files it does not understand."""

import json
import os

from .atomic import write_bytes

MANIFEST_NAME = "manifest.json"
FORMAT_VERSION = 1


def manifest_path(folder, name=MANIFEST_NAME):
    return os.path.join(folder, name)


def read_manifest(folder, kind, name=MANIFEST_NAME):
    """The manifest `name` of `kind` as a dict, or None when missing, unreadable, of another kind
    or of another format version."""
    try:
        with open(manifest_path(folder, name), "r", encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("format_version") != FORMAT_VERSION:
        return None
    if data.get("kind") != kind:
        return None
    return data


def write_manifest(folder, data, name=MANIFEST_NAME):
    """Writes `data` (with its "kind" and "format_version") as the folder's manifest `name`,
    atomically."""
    text = json.dumps(data, indent=1, sort_keys=True)
    write_bytes(manifest_path(folder, name), text.encode("utf-8"))

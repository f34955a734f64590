"""The job file: what a job's child needs, as a small versioned file in its cache folder, no
``bpy`` (DESIGN.md "Layers").

    <cache folder>/jobs/<kind>.json     format, version, kind, title, add-on version, the spec
    <cache folder>/jobs/<kind>.npz      the spec's arrays (meshes, matrices, images)
    <cache folder>/jobs/<kind>.log      what the child printed (its tracebacks, a fatal signal)
    <cache folder>/jobs/<kind>.result.json/.npz   what run() returned, written by the child

The spec is plain data: numbers, strings, lists, tuples, dicts, NumPy arrays, enums and the
add-on's dataclasses (settings snapshots, results), encoded by name and rebuilt field by field,
so the child needs neither Blender nor pickles. A string naming a path inside the cache folder
is stored relative to it, so the job runs from a copy of the folder at another path (a farm
node that mounts it elsewhere). The files of a job that ended well are removed; a crashed or
killed job keeps its job file and log (run it again with ``python -m plume.job run <folder>``).
"""

import dataclasses
import enum
import importlib
import io
import json
import os
import re
import socket
import time

import numpy as np

from ..files import write_bytes
from ..version import VERSION

FORMAT = "plume-job"
#: Version of the job file; a child refuses a newer one (written by a newer add-on).
FORMAT_VERSION = 1
#: The folder of the job files inside a cache folder.
JOBS_FOLDER = "jobs"
_PACKAGE = __name__.rsplit(".", 2)[0]  # "plume" (or "bl_ext.user_default.plume")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.]*$")


class JobFileError(ValueError):
    """A job file that cannot be read (missing, damaged, from a newer Plume)."""


def job_paths(folder, name):
    """dict of the paths of job `name` (its kind, unless two may run there) in `folder`."""
    base = os.path.join(folder, JOBS_FOLDER, name)
    return {"json": base + ".json", "npz": base + ".npz", "log": base + ".log",
            "result": base + ".result.json", "result_npz": base + ".result.npz"}


# ---------------------------------------------------------------------- encoding
class _Encoder:
    """Plain data -> JSON-able values; arrays collected for the .npz beside."""

    def __init__(self, root):
        self.root = os.path.abspath(root) if root else None
        self.arrays = {}

    def encode(self, v):
        if v is None or isinstance(v, (bool, int, float)):
            return v
        if isinstance(v, str):
            return self._string(v)
        if isinstance(v, np.ndarray):
            key = f"a{len(self.arrays)}"
            self.arrays[key] = v
            return {"__array__": key}
        if isinstance(v, np.generic):
            return v.item()
        if isinstance(v, enum.Enum):
            return {"__enum__": _type_name(type(v)), "name": v.name}
        if dataclasses.is_dataclass(v) and not isinstance(v, type):
            return {"__dataclass__": _type_name(type(v)),
                    "fields": {f.name: self.encode(getattr(v, f.name))
                               for f in dataclasses.fields(v)}}
        if isinstance(v, tuple):
            return {"__tuple__": [self.encode(x) for x in v]}
        if isinstance(v, list):
            return [self.encode(x) for x in v]
        if isinstance(v, dict):
            if all(isinstance(k, str) and not k.startswith("__") for k in v):
                return {k: self.encode(x) for k, x in v.items()}
            return {"__pairs__": [[self.encode(k), self.encode(x)] for k, x in v.items()]}
        raise TypeError(f"a job cannot carry {type(v).__module__}.{type(v).__name__} ({v!r:.80})")

    def _string(self, s):
        root = self.root
        if root and os.path.isabs(s):
            norm = os.path.normpath(s)
            if norm == root or norm.startswith(root + os.sep):
                return {"__path__": os.path.relpath(norm, root)}
        return s


def _type_name(cls):
    module = cls.__module__
    if module == _PACKAGE or not module.startswith(_PACKAGE + "."):
        raise TypeError(f"a job carries only Plume's own types, not {module}.{cls.__qualname__}")
    return f"{module[len(_PACKAGE) + 1:]}:{cls.__qualname__}"


def _resolve(name):
    module, _, qual = name.partition(":")
    if not (_NAME.match(module) and _NAME.match(qual)):
        raise JobFileError(f"bad type name {name!r}")
    obj = importlib.import_module(f"{_PACKAGE}.{module}")
    for part in qual.split("."):
        obj = getattr(obj, part)
    return obj


class _Decoder:
    def __init__(self, root, arrays):
        self.root, self.arrays = root, arrays

    def decode(self, v):
        if isinstance(v, list):
            return [self.decode(x) for x in v]
        if not isinstance(v, dict):
            return v
        if "__array__" in v:
            return self.arrays[v["__array__"]]
        if "__path__" in v:
            return os.path.normpath(os.path.join(self.root, v["__path__"]))
        if "__tuple__" in v:
            return tuple(self.decode(x) for x in v["__tuple__"])
        if "__pairs__" in v:
            return {_hashable(self.decode(k)): self.decode(x) for k, x in v["__pairs__"]}
        if "__enum__" in v:
            return _resolve(v["__enum__"])[v["name"]]
        if "__dataclass__" in v:
            cls = _resolve(v["__dataclass__"])
            if not dataclasses.is_dataclass(cls):
                raise JobFileError(f"{v['__dataclass__']} is not a dataclass")
            obj = object.__new__(cls)  # field by field, as written (frozen ones too)
            for name, x in v["fields"].items():
                object.__setattr__(obj, name, self.decode(x))
            return obj
        return {k: self.decode(x) for k, x in v.items()}


def _hashable(k):
    return tuple(_hashable(x) for x in k) if isinstance(k, list) else k


def _npz_bytes(arrays):
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _load_arrays(path, wanted):
    if not wanted:
        return {}
    try:
        with np.load(path, allow_pickle=False) as data:
            return {k: np.array(data[k]) for k in wanted}
    except (OSError, KeyError, ValueError) as e:
        raise JobFileError(f"{path}: {e}") from None


def _wanted(v, out):
    if isinstance(v, dict):
        if "__array__" in v:
            out.add(v["__array__"])
        else:
            for x in v.values():
                _wanted(x, out)
    elif isinstance(v, list):
        for x in v:
            _wanted(x, out)
    return out


def dump(value, json_path, npz_path, root, header=None):
    """Writes `value` (plain data, see the module comment) to json_path + npz_path atomically;
    paths under `root` are stored relative to it. The arrays are written first, so a JSON file
    that exists always has its arrays."""
    enc = _Encoder(root)
    body = dict(header or {})
    body["value"] = enc.encode(value)
    os.makedirs(os.path.dirname(json_path), exist_ok=True)
    if enc.arrays:
        write_bytes(npz_path, _npz_bytes(enc.arrays))
    write_bytes(json_path, json.dumps(body, indent=1, allow_nan=True).encode("utf-8"))


def load(json_path, npz_path, root):
    """(header dict, value) of a file written by dump(); JobFileError when unreadable."""
    try:
        with open(json_path, "rb") as f:
            body = json.loads(f.read().decode("utf-8"))
    except FileNotFoundError:
        raise JobFileError(f"no job file {json_path}") from None
    except (OSError, ValueError) as e:
        raise JobFileError(f"{json_path} cannot be read: {e}") from None
    if not isinstance(body, dict) or "value" not in body:
        raise JobFileError(f"{json_path} is not a Plume job file")
    raw = body.pop("value")
    arrays = _load_arrays(npz_path, _wanted(raw, set()))
    try:
        return body, _Decoder(root, arrays).decode(raw)
    except (ImportError, AttributeError, KeyError, TypeError) as e:
        raise JobFileError(f"{json_path}: {e}") from None


# ---------------------------------------------------------------------- the job file itself
def write_job(folder, kind, title, spec, name=None):
    """Writes the job file of `kind` in cache folder `folder` (as jobs/<name>.json, name
    defaults to the kind); its path."""
    paths = job_paths(folder, name or kind)
    header = {"format": FORMAT, "version": FORMAT_VERSION, "kind": kind, "title": title,
              "addon_version": VERSION, "written_by": socket.gethostname(),
              "written_at": time.strftime("%Y-%m-%d %H:%M:%S")}
    dump(spec, paths["json"], paths["npz"], folder, header)
    return paths["json"]


def find_job(target):
    """The job file named by `target`: a job file, or a cache folder holding exactly one job
    (JobFileError otherwise, listing them)."""
    if os.path.isfile(target):
        return os.path.abspath(target)
    folder = os.path.join(target, JOBS_FOLDER)
    names = sorted(n for n in os.listdir(folder) if n.endswith(".json")
                   and not n.endswith(".result.json")) if os.path.isdir(folder) else []
    if len(names) != 1:
        what = ", ".join(names) if names else "none"
        raise JobFileError(f"{target}: expected one job file in {folder} (found {what}); name "
                           "the job file")
    return os.path.abspath(os.path.join(folder, names[0]))


def read_job(job_file):
    """(header, spec, cache folder) of a job file; JobFileError when it cannot be run here."""
    job_file = os.path.abspath(job_file)
    folder = os.path.dirname(os.path.dirname(job_file))
    npz = job_file[:-len(".json")] + ".npz"
    header, spec = load(job_file, npz, folder)
    if header.get("format") != FORMAT:
        raise JobFileError(f"{job_file} is not a Plume job file")
    if not isinstance(header.get("version"), int) or header["version"] > FORMAT_VERSION:
        raise JobFileError(f"{job_file} was written by a newer Plume ({header.get('addon_version')}"
                           f", job format {header.get('version')}); this is {VERSION}: install "
                           "the same Plume here")
    return header, spec, folder


def remove_job(folder, name, keep_log=False):
    """Removes the job files of `name` (the log too unless keep_log), and the jobs folder when
    it ends up empty."""
    for key, path in job_paths(folder, name).items():
        if key == "log" and keep_log:
            continue
        try:
            os.remove(path)
        except OSError:
            pass
    try:
        os.rmdir(os.path.join(folder, JOBS_FOLDER))
    except OSError:
        pass

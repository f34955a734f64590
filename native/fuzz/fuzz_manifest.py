#!/usr/bin/env python3
"""Fuzz driver of the cache manifests (addon/files/manifest.py), the in-process Python
equivalent of the libFuzzer targets: a deterministic mutation loop over seed manifests written
by the add-on's own writer (write_manifest).

Property, on any bytes: read_manifest(folder, kind) never raises and never stalls (its
documented answer to a missing, unreadable or damaged manifest is None, after which the bake
starts over); what it returns is None or a dict of the asked kind and format version on which
every expression the add-on applies to a manifest without checking (comparisons of the frame
fields, int()/float() of the grid fields, dict/list methods) works.

Why no atheris: its coverage guidance would see little in a reader that is json.loads plus a
few type checks, its wheels need pip in /usr/bin/python3 (Debian's is externally managed), and
CI must not depend on PyPI; a seeded loop with JSON-aware mutations reaches the same cases and
is reproducible from (--seed, case number).

  fuzz_manifest.py --seconds 30          fuzz for 30 s (or --cases N), seed 0 (or --seed K)
  fuzz_manifest.py FILE_OR_DIR ...       replay saved inputs (regressions/manifest/), then fuzz
                                         only if --cases/--seconds is given
Findings are written to --save (default ./manifest-findings/) and make the exit status 1.
"""

import argparse
import hashlib
import json
import math
import os
import random
import shutil
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "addon"))
from files import manifest  # noqa: E402  (addon/files, bpy-free)

STALL_SECONDS = 1.0
KINDS = ("smoke", "flames")

VALUES = [None, True, False, 0, -1, 1, 7, 2**31, -2**31 - 1, 2**63, -2**63, 10**40, 0.5, -0.0,
          1e308, float("nan"), float("inf"), float("-inf"), "", "x", "smoke", "flames", "é\u2603",
          [], {}, [1, 2], [1, 2, 3], [0, 0, 0], [-1, 4, 4], ["a", "b", "c"], [1.5, "x", None],
          {"solver": 3}, {"solver": {}}, {"a": [1, {"b": None}]}]
TOKENS = [b"[", b"]", b"{", b"}", b",", b":", b'"', b"\\", b"\\u", b"\\ud800", b"null", b"true",
          b"NaN", b"Infinity", b"-Infinity", b"1e999", b"-0", b"0x10", b"\xff", b"\xc3", b"\x00",
          b"\xed\xa0\x80", b"1" * 5000]


def seed_manifests():
    """(kind, dict) of what the writers write: a smoke bake, a Mantaflow-traced bake, flames."""
    settings = {"solver": {"resolution": [32, 32, 48], "origin": [-1.0, -1.0, 0.0],
                           "interpolation": "LINEAR", "frame_dt": 1 / 24},
                "streaks": {"emission_period": 2}}
    smoke = {"format_version": 1, "addon_version": "0.1.0", "kind": "smoke", "domain": "Domain",
             "settings": settings, "frame_start": 1, "frame_end": 24, "resolution": [32, 32, 48],
             "cell_size": 0.0625, "origin": [-1.0, -1.0, 0.0], "combustion": False,
             "streaks": True, "emission_period": 2, "last_complete_frame": 12, "state_frame": 10,
             "frame_inputs": ["a1b2", "c3d4"], "frames_computed_total": 12,
             "last_run": {"resumed": False, "computed_frames": [11, 12], "cancelled": True}}
    manta = dict(smoke, motion_source="mantaflow", mantaflow_domain="Smoke",
                 cell_size_xyz=[0.05, 0.05, 0.0625], state_frame=None)
    flames = {"format_version": 1, "kind": "flames", "frame_start": 1, "frame_end": 10,
              "last_complete_frame": 10, "seed": 3, "substeps": 2, "sources": ["Candle"],
              "settings": {"intensity": 1.0}, "flames": [2, 3], "particles": [100, 120]}
    return [("smoke", smoke), ("smoke", manta), ("flames", flames)]


def consume(m, kind):
    """What the add-on does with a manifest it got back (cache_state, toon, streak_surfaces,
    bake_runner, operators/surfaces, flame_smoke); raises on a manifest it cannot use."""
    if m is None:
        return
    assert isinstance(m, dict), f"not a dict: {type(m)}"
    assert m.get("kind") == kind and m.get("format_version") == manifest.FORMAT_VERSION
    max(0, min(m.get("last_complete_frame", 0), 100) - m.get("frame_start", 1) + 1)
    bool(m.get("last_complete_frame", -1) < m.get("frame_start", 0))
    for field in ("frame_start", "frame_end", "last_complete_frame"):
        if field in m:
            int(m[field])
    first, last = m.get("frame_start"), m.get("last_complete_frame")
    if isinstance(first, int) and isinstance(last, int):
        first <= last  # noqa: B015
    state = m.get("state_frame")
    if state is not None:
        bool(0 <= state <= 10)
    m.get("frame_inputs", [])[:3]
    m.get("settings", {}).get("solver")
    m.get("last_run", {}).get("cancelled")
    if "frames_computed_total" in m:
        m["frames_computed_total"] + 1
    if "resolution" in m:
        res = tuple(int(v) for v in m["resolution"])
        assert len(res) == 3 and min(res) >= 1, f"resolution {res}"
    if "origin" in m:
        origin = tuple(float(v) for v in m["origin"])
        assert len(origin) == 3 and all(map(math.isfinite, origin)), f"origin {origin}"
    if "cell_size" in m:
        cell = float(m["cell_size"])
        assert math.isfinite(cell) and cell > 0, f"cell_size {cell}"
    if "cell_size_xyz" in m:
        cells = [float(v) for v in m["cell_size_xyz"]]
        assert len(cells) == 3 and all(math.isfinite(c) and c > 0 for c in cells)


def _nodes(value, path=()):
    yield path, value
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _nodes(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _nodes(v, path + (i,))


def _set(root, path, value):
    if not path:
        return value
    node = root
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    return root


def mutate_json(rng, data):
    """A structural mutation: a node replaced, a key deleted or added, or deep nesting."""
    data = json.loads(json.dumps(data))
    nodes = list(_nodes(data))
    path, _ = rng.choice(nodes)
    op = rng.random()
    if op < 0.6:
        data = _set(data, path, json.loads(json.dumps(rng.choice(VALUES))))
    elif op < 0.75 and path:
        parent = data
        for p in path[:-1]:
            parent = parent[p]
        del parent[path[-1]]
    elif op < 0.9:
        dicts = [v for _, v in nodes if isinstance(v, dict)]
        if dicts:
            rng.choice(dicts)[rng.choice(["frame_start", "state_frame", "settings", "resolution",
                                          "cell_size", "kind", "zz"])] = rng.choice(VALUES)
    else:
        depth = rng.choice([10, 1000, 100000])
        deep = json.loads("[" * min(depth, 500) + "]" * min(depth, 500))
        data = _set(data, path, deep) if depth <= 500 else data
        if depth > 500:
            text = json.dumps(data)
            cut = rng.randrange(len(text) + 1)
            return (text[:cut] + "[" * depth + "]" * depth + text[cut:]).encode()
    return json.dumps(data, indent=rng.choice([None, 1])).encode("utf-8")


def mutate_bytes(rng, raw, seeds):
    b = bytearray(raw)
    for _ in range(rng.choice([1, 1, 2, 4, 8])):
        op = rng.randrange(7)
        pos = rng.randrange(len(b) + 1)
        if op == 0 and b:
            b[min(pos, len(b) - 1)] ^= 1 << rng.randrange(8)
        elif op == 1 and b:
            b[min(pos, len(b) - 1)] = rng.randrange(256)
        elif op == 2:
            b[pos:pos] = rng.choice(TOKENS)
        elif op == 3:
            del b[pos:pos + rng.choice([1, 2, 8, 64])]
        elif op == 4:
            del b[pos:]
        elif op == 5 and b:
            start = rng.randrange(len(b))
            b[pos:pos] = b[start:start + rng.choice([4, 32, 256])]
        else:
            other = rng.choice(seeds)
            b[pos:] = other[rng.randrange(len(other) + 1):]
    return bytes(b)


class Driver:
    def __init__(self, save):
        self.folder = tempfile.mkdtemp(prefix="plume_fuzz_manifest_",
                                       dir="/dev/shm" if os.path.isdir("/dev/shm") else None)
        self.path = manifest.manifest_path(self.folder)
        self.save = save
        self.findings = 0
        self.cases = 0
        self.slowest = 0.0
        self.stalls = 0

    def close(self):
        shutil.rmtree(self.folder, ignore_errors=True)

    def run(self, raw, kind):
        with open(self.path, "wb") as f:
            f.write(raw)
        self.cases += 1
        t0 = time.perf_counter()
        try:
            m = manifest.read_manifest(self.folder, kind)
        except BaseException as e:  # noqa: BLE001  every escape is a finding
            return self.finding(raw, f"read_manifest raised {type(e).__name__}: {e}"[:300])
        elapsed = time.perf_counter() - t0
        self.slowest = max(self.slowest, elapsed)
        if elapsed > STALL_SECONDS:
            self.stalls += 1
            return self.finding(raw, f"read_manifest took {elapsed:.2f} s")
        try:
            consume(m, kind)
        except Exception as e:  # noqa: BLE001
            return self.finding(raw, f"the add-on cannot use the returned manifest: "
                                     f"{type(e).__name__}: {e}"[:300])

    def finding(self, raw, what):
        self.findings += 1
        os.makedirs(self.save, exist_ok=True)
        name = os.path.join(self.save, "finding-" + hashlib.sha1(raw).hexdigest()[:16] + ".json")
        with open(name, "wb") as f:
            f.write(raw)
        print(f"manifest finding: {what} (input saved as {name})", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("inputs", nargs="*", help="files or folders of saved inputs to replay")
    ap.add_argument("--cases", type=int, default=0)
    ap.add_argument("--seconds", type=float, default=0.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--save", default="manifest-findings")
    args = ap.parse_args(argv)

    driver = Driver(args.save)
    try:
        replayed = 0
        for item in args.inputs:
            paths = ([os.path.join(item, n) for n in sorted(os.listdir(item))]
                     if os.path.isdir(item) else [item] if os.path.isfile(item) else [])
            for p in paths:
                with open(p, "rb") as f:
                    raw = f.read()
                for kind in KINDS:
                    driver.run(raw, kind)
                replayed += 1
        seeds = []
        for kind, data in seed_manifests():
            manifest.write_manifest(driver.folder, data)
            with open(driver.path, "rb") as f:
                seeds.append((kind, f.read(), data))
        for kind, raw, _ in seeds:
            driver.run(raw, kind)
            assert manifest.read_manifest(driver.folder, kind) == json.loads(raw), "seed refused"
        raws = [raw for _, raw, _ in seeds]
        rng = random.Random(args.seed)
        t_end = time.monotonic() + args.seconds
        fuzzed = 0
        while (args.cases and fuzzed < args.cases) or (args.seconds and time.monotonic() < t_end):
            kind, raw, data = rng.choice(seeds)
            if rng.random() < 0.5:
                raw = mutate_json(rng, data)
            if rng.random() < 0.6:
                raw = mutate_bytes(rng, raw, raws)
            driver.run(raw, kind if rng.random() < 0.9 else rng.choice(KINDS))
            fuzzed += 1
        print(f"manifest: {driver.cases} cases run ({replayed} replayed, {fuzzed} fuzzed, "
              f"seed {args.seed}), findings: {driver.findings} "
              f"(stalls > {STALL_SECONDS:g} s: {driver.stalls}), "
              f"slowest read {driver.slowest * 1e3:.1f} ms", flush=True)
    finally:
        driver.close()
    return 1 if driver.findings else 0


if __name__ == "__main__":
    sys.exit(main())

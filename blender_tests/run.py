#!/usr/bin/env python3
"""Runs Plume's Blender tests under any of the Blenders Plume supports, or all of them.

    blender_tests/run.py --blender 4.5 test_bake.py            # one file in one Blender
    blender_tests/run.py --blender 5.0 test_bake.py -- BakeTest.test_cache_free
    blender_tests/run.py --blender all                          # every file in every Blender
    blender_tests/run.py --setup all                            # create the bpy venvs only
    blender_tests/run.py --blender 4.5 --script examples/smoke/compare_mantaflow.py -- 64 48

Blenders: "3.4" is Debian 12's packaged 3.4.1 (``blender -b --factory-startup``); "4.5" and "5.0"
are the ``bpy`` wheels from the Python package index, pinned below, each in its own CPython 3.11
venv under $PLUME_VENV_ROOT (default ~/.cache/plume/venvs), created once by --setup and reused.
A test file under a ``bpy`` module runs in ``<venv>/bin/python`` after ``import bpy``: the same
script, the same operators, no window. Each Blender's renders go to $PLUME_TEST_OUT/<x.y>/
(default /tmp/plume_test_out/<x.y>/), to compare them. The add-on must be installed where each
Blender finds user add-ons ($BLENDER_USER_SCRIPTS/addons/plume, else
~/.config/blender/<x.y>/scripts/addons/plume); .ci/common.sh does that.

Each file prints "N passed, N failed" on its last line (helpers.run); this runner adds them up and
prints them per Blender and in total, and exits 1 when anything failed."""

import argparse
import glob
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))

#: Blender label -> exact bpy wheel version (None: the system's `blender` executable).
BPY_PINS = {"3.4": None, "4.5": "4.5.15", "5.0": "5.0.1"}
#: Files that need a window (Xvfb + the real executable): only the packaged Blender has one.
WINDOWED = {"test_ui_jobs.py"}
#: The interpreter the venvs are made from: Debian's CPython 3.11, the _native module's ABI.
VENV_PYTHON = "/usr/bin/python3"
TIMEOUT_S = 1800

_SUMMARY = re.compile(r"^(\d+) passed, (\d+) failed\s*$", re.M)


def venv_root():
    return os.environ.get("PLUME_VENV_ROOT", os.path.expanduser("~/.cache/plume/venvs"))


def venv_python(label):
    return os.path.join(venv_root(), f"bpy-{BPY_PINS[label]}", "bin", "python")


def setup(label):
    """Creates (once) the venv of a bpy Blender and installs the pinned wheel into it."""
    pin = BPY_PINS[label]
    if pin is None:
        return
    py = venv_python(label)
    probe = [py, "-c", f"import importlib.metadata as m; assert m.version('bpy') == '{pin}'"]
    if os.path.exists(py) and subprocess.run(probe, capture_output=True).returncode == 0:
        print(f"== bpy {pin}: venv ready ({os.path.dirname(os.path.dirname(py))})", flush=True)
        return
    env_dir = os.path.dirname(os.path.dirname(py))
    print(f"== bpy {pin}: creating {env_dir}", flush=True)
    subprocess.run([VENV_PYTHON, "-m", "venv", "--clear", env_dir], check=True)
    subprocess.run([py, "-m", "pip", "install", "-q", "--disable-pip-version-check",
                    f"bpy=={pin}"], check=True)


def command(label, path, names):
    """The command line that runs one test file in one Blender."""
    tail = ["--", *names] if names else []
    if BPY_PINS[label] is None:
        return ["blender", "-b", "--factory-startup", "--python-exit-code", "1",
                "--python", path, *tail]
    py = venv_python(label)
    if not os.path.exists(py):
        raise SystemExit(f"run.py: no venv for Blender {label} ({py}); create it with "
                         f"{sys.argv[0]} --setup {label}")
    # bpy first, as inside Blender: it puts Blender's own modules (addon_utils, bl_*) on sys.path.
    boot = ("import runpy, sys, bpy; sys.argv = sys.argv[1:]; "
            "runpy.run_path(sys.argv[0], run_name='__main__')")
    return [py, "-c", boot, path, *tail]


def clean_env():
    """The environment for a test process, without a pyenv's PATH entries: Debian's Blender looks
    for its Python home along PATH and, finding pyenv's 3.11, loses /usr/lib/python3/dist-packages
    (numpy, the add-on's only dependency)."""
    env = dict(os.environ)
    root = env.get("PYENV_ROOT")
    if root:
        env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep)
                                      if not p.startswith(root))
        for k in [k for k in env if k.startswith("PYENV")]:
            del env[k]
    return env


def run_file(label, path, names):
    """(passed, failed) test counts of one file; a file that crashes or prints no summary counts
    as one failure."""
    start = time.monotonic()
    print(f"-- [{label}] {os.path.basename(path)}", flush=True)
    try:
        env = clean_env()  # each Blender's renders in a folder of its own, to compare them
        env["PLUME_TEST_OUT"] = os.path.join(
            os.environ.get("PLUME_TEST_OUT", "/tmp/plume_test_out"), label)
        proc = subprocess.run(command(label, path, names), stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, timeout=TIMEOUT_S, env=env)
        out, rc = proc.stdout, proc.returncode
    except subprocess.TimeoutExpired as e:
        out, rc = (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) \
            else (e.stdout or ""), "timeout"
    sys.stdout.write(out)
    found = _SUMMARY.findall(out)
    passed, failed = (int(found[-1][0]), int(found[-1][1])) if found else (0, 0)
    if rc != 0 and failed == 0:
        failed = 1  # crashed, or failed outside a test case
    status = "ok" if rc == 0 else f"FAILED (rc {rc})"
    print(f"-- [{label}] {os.path.basename(path)}: {passed} passed, {failed} failed, {status}, "
          f"{time.monotonic() - start:.0f} s", flush=True)
    return passed, failed


def main(argv):
    args_, names = (argv[:argv.index("--")], argv[argv.index("--") + 1:]) if "--" in argv \
        else (argv, [])
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--blender", default="3.4", choices=[*BPY_PINS, "all"])
    ap.add_argument("--setup", choices=[*BPY_PINS, "all"],
                    help="create the venv(s) of the bpy Blender(s) and stop")
    ap.add_argument("--script", help="run this script (an example, a benchmark) in the Blender "
                    "given by --blender, passing the arguments after --, and exit with its code")
    ap.add_argument("files", nargs="*", help="test files (default: every blender_tests/test_*.py)")
    a = ap.parse_args(args_)
    if a.setup:
        for label in (BPY_PINS if a.setup == "all" else [a.setup]):
            setup(label)
        return 0
    labels = list(BPY_PINS) if a.blender == "all" else [a.blender]
    if a.script:
        return max(subprocess.run(command(label, os.path.abspath(a.script), names),
                                  env=clean_env()).returncode for label in labels)
    files = [f if os.path.exists(f) else os.path.join(HERE, f) for f in a.files] or \
        sorted(glob.glob(os.path.join(HERE, "test_*.py")))
    totals = {}
    for label in labels:
        p = f = 0
        for path in files:
            if BPY_PINS[label] is not None and os.path.basename(path) in WINDOWED:
                continue  # bpy has no window; the UI test runs in the packaged Blender
            dp, df = run_file(label, path, names)
            p, f = p + dp, f + df
        totals[label] = (p, f)
    print("== Blender tests")
    for label, (p, f) in totals.items():
        name = "3.4.1 (Debian blender)" if BPY_PINS[label] is None else f"{BPY_PINS[label]} (bpy)"
        print(f"Blender {name}: {p} passed, {f} failed")
    tp, tf = sum(v[0] for v in totals.values()), sum(v[1] for v in totals.values())
    print(f"all Blenders: {tp} passed, {tf} failed")
    return 0 if tf == 0 and tp > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

#!/usr/bin/env python3
"""Runs Plume's Blender tests under any of the Blenders Plume supports, or all of them.

    blender_tests/run.py --blender 4.5 test_bake.py            # one file in one Blender
    blender_tests/run.py --blender 5.0 test_bake.py -- BakeTest.test_cache_free
    blender_tests/run.py --blender all                          # every Blender, as the policy says
    blender_tests/run.py --blender all --list                   # which files each Blender runs
    blender_tests/run.py --setup all                            # create the bpy venvs only
    blender_tests/run.py --blender 4.5 --script examples/smoke/compare_mantaflow.py -- 64 48

Blenders, 4.2 LTS to 5.3: "3.4" is Debian 12's packaged 3.4.1 (``blender -b --factory-startup``);
"4.2", "4.5", "5.0" and "5.3" are the ``bpy`` wheels from the Python package index, pinned below,
each in a venv ~/.cache/plume/venvs/bpy-<version> ($PLUME_VENV_ROOT), created once by --setup
(again when its ``import bpy`` fails) and reused. 4.2 to 5.0 are cp311 wheels, their venvs made
from Debian's /usr/bin/python3; Blender 5.1+ bundles CPython 3.13, so 5.3's venv is made from a
CPython 3.13 found by pythons.py ($PLUME_PYTHON313, else pyenv's newest 3.13.x, else python3.13
on PATH). A test file under a ``bpy`` module runs in ``<venv>/bin/python`` after ``import bpy``:
the same script, the same operators, no window.

Which files run where (CI has a time budget): "3.4" (with the windowed UI test) and the newest,
"5.3", run every test_*.py; 4.2, 4.5 and 5.0 run SUBSET below (the zip install and one end-to-end
file per pipeline). ``--full`` runs every file everywhere; files named on the command line always
run as asked. WINDOWED files run in 3.4 only. Each Blender's renders go to $PLUME_TEST_OUT/<x.y>/
(default /tmp/plume_test_out/<x.y>/), to compare them. The add-on must be installed where each
Blender finds user add-ons ($BLENDER_USER_SCRIPTS/addons/plume, else
~/.config/blender/<x.y>/scripts/addons/plume); .ci/common.sh does that.

Each file prints "N passed, N failed, N skipped" on its last line (helpers.run: a skip must say
what the machine lacks, else it counts as failed); this runner adds them up and prints them per
Blender and in total, then a table per Blender (files, passed, failed, skipped, the files that
failed), and exits 1 when anything failed."""

import argparse
import glob
import os
import re
import subprocess
import sys
import time

import pythons  # this folder is sys.path[0]: run.py runs as a script

HERE = os.path.dirname(os.path.abspath(__file__))

#: Blender label -> exact bpy wheel version (None: the system's `blender` executable), oldest
#: first. 4.2.23 is the newest 4.2 LTS wheel on the index; 5.3.0 is cp313 (pythons.py).
BPY_PINS = {"3.4": None, "4.2": "4.2.23", "4.5": "4.5.15", "5.0": "5.0.1", "5.3": "5.3.0"}
#: Blenders that run every test_*.py: the packaged one (it alone has the windowed UI test) and
#: the newest.
FULL = {"3.4", "5.3"}
#: What the other Blenders run: the zip install and, per pipeline, the one file that takes it end
#: to end through the operators to a Cycles render whose pixels it checks.
SUBSET = [
    "test_install_zip.py",     # the zip installed as an artist does; a 32³ bake renders smoke
    "test_bake.py",            # solver: bake, Volume sequence, VDB grids, render, free, resume
    "test_streak_surfaces.py",  # streak surfaces: streak bake, Build Surfaces, render is sheets
    "test_toon_smoke.py",      # toon smoke: Build Toon Smoke, render's outline = _native's
    "test_toon_outline_width.py",  # toon outline width scales with the render, soft edges
    "test_flowgraph_fire.py",  # flow-graph fire: 2 states, Flow Graph, Synthesize Fire, render
    "test_flames.py",          # structural flames: Bake Flames, grids, spines, lights, render
    "test_flame_presets.py",   # flames' look per Blender's own view transform, presets, stops
    "test_fire_look.py",       # combustion fire under the default view transform: hue, taper
    "test_job_child.py",       # jobs in a child: injected crashes cost the job, resume, CLI
]
#: bpy wheels whose process teardown crashes after the tests: the 4.2 module frees registered
#: classes in C++ static destructors after Python has ended (SIGSEGV in bpy_class_free under
#: SpaceType::~SpaceType) once any add-on registered PropertyGroups or a Panel, even when they
#: were unregistered again (a bare Panel registration in an empty script does it too; 4.5 and
#: later exit cleanly). Their test processes end with os._exit after the file's own result, so
#: the tests' verdict is kept and the teardown is skipped; README "Tested Blenders" says so.
EXIT_WITHOUT_TEARDOWN = {"4.2"}
#: Files that run in the packaged Blender only under the policy (named on the command line they
#: run anywhere): the farm tests start a Blender per task on the single-node Slurm cluster,
#: minutes per run, and what they test (Slurm, paths, resume) does not change with the Blender;
#: the same for the farm job run by Open Job Description's runner. test_streak_net (2-2.5 min a
#: Blender: the Figure 1 incense at 50³ over 120 frames and three more bakes) measures the
#: least-squares nets of the core and streak_surfaces.py; the NURBS objects Blender makes of them
#: are checked in every Blender by test_streak_surfaces (SUBSET) and, in 5.3, the other streak
#: files.
ONE_BLENDER = {"test_farm.py", "test_farm_flowgraph.py", "test_farm_openjd.py",
               "test_streak_net.py"}
#: Files that need a window (Xvfb + the real executable): only the packaged Blender has one.
WINDOWED = {"test_farm_window.py", "test_ui_jobs.py", "test_ui_screenshots.py"}
TIMEOUT_S = 1800

_SUMMARY = re.compile(r"^(\d+) passed, (\d+) failed(?:, (\d+) skipped)?\s*$", re.M)


def venv_root():
    return os.environ.get("PLUME_VENV_ROOT", os.path.expanduser("~/.cache/plume/venvs"))


def venv_python(label):
    return os.path.join(venv_root(), f"bpy-{BPY_PINS[label]}", "bin", "python")


def bpy_works(label):
    """Whether the venv of a bpy Blender imports its pinned bpy (a venv whose interpreter went,
    or a half-installed wheel, does not)."""
    py, pin = venv_python(label), BPY_PINS[label]
    probe = [py, "-c", "import importlib.metadata as m, bpy; "
             f"assert m.version('bpy') == '{pin}', m.version('bpy')"]
    try:
        return os.path.exists(py) and subprocess.run(
            probe, capture_output=True, timeout=300, env=clean_env()).returncode == 0
    except subprocess.TimeoutExpired:
        return False


def base_python(label):
    """The CPython a bpy Blender's venv is made from; exits with pythons.py's reason if none."""
    try:
        return pythons.python_for(pythons.cpython_of_blender(label))
    except pythons.PythonNotFound as e:
        raise SystemExit(f"run.py: Blender {label}: {e}")


def setup(label):
    """Creates the venv of a bpy Blender and installs the pinned wheel into it, unless it is
    there and imports bpy; a venv that exists but does not is made again from scratch."""
    pin = BPY_PINS[label]
    if pin is None:
        return
    py = venv_python(label)
    env_dir = os.path.dirname(os.path.dirname(py))
    if bpy_works(label):
        print(f"== bpy {pin}: venv ready ({env_dir})", flush=True)
        return
    base = base_python(label)
    again = "re-creating (import bpy failed)" if os.path.exists(env_dir) else "creating"
    print(f"== bpy {pin}: {again} {env_dir} from {base}", flush=True)
    subprocess.run([base, "-m", "venv", "--clear", env_dir], check=True)
    subprocess.run([py, "-m", "pip", "install", "-q", "--disable-pip-version-check",
                    f"bpy=={pin}"], check=True)
    if not bpy_works(label):
        raise SystemExit(f"run.py: bpy {pin} is installed in {env_dir} but `import bpy` fails "
                         f"there; try: {py} -c 'import bpy'")


def require_venv(label):
    """The Python of a bpy Blender's venv; exits saying how to make it when there is none (or,
    first, that there is no CPython to make it from)."""
    py = venv_python(label)
    if not os.path.exists(py):
        base_python(label)
        raise SystemExit(f"run.py: no venv for Blender {label} ({py}); create it with "
                         f"{sys.argv[0]} --setup {label}")
    return py


def command(label, path, names):
    """The command line that runs one test file in one Blender."""
    tail = ["--", *names] if names else []
    if BPY_PINS[label] is None:
        return ["blender", "-b", "--factory-startup", "--python-exit-code", "1",
                "--python", path, *tail]
    py = require_venv(label)
    # bpy first, as inside Blender: it puts Blender's own modules (addon_utils, bl_*) on sys.path.
    boot = ("import runpy, sys, bpy; sys.argv = sys.argv[1:]; "
            "runpy.run_path(sys.argv[0], run_name='__main__')")
    if label in EXIT_WITHOUT_TEARDOWN:
        # The file's own exit code (its summary is printed), then os._exit: see the set's note.
        boot = ("import os, runpy, sys, bpy; sys.argv = sys.argv[1:]\n"
                "try:\n    runpy.run_path(sys.argv[0], run_name='__main__'); code = 0\n"
                "except SystemExit as e:\n"
                "    code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)\n"
                "sys.stdout.flush(); sys.stderr.flush(); os._exit(code)")
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
    """(passed, failed, skipped) test counts of one file; a file that crashes or prints no
    summary counts as one failure."""
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
    passed, failed, skipped = ((int(found[-1][0]), int(found[-1][1]), int(found[-1][2] or 0))
                               if found else (0, 0, 0))
    if rc != 0 and failed == 0:
        failed = 1  # crashed, or failed outside a test case
    status = "ok" if rc == 0 else f"FAILED (rc {rc})"
    print(f"-- [{label}] {os.path.basename(path)}: {passed} passed, {failed} failed, "
          f"{skipped} skipped, {status}, {time.monotonic() - start:.0f} s", flush=True)
    return passed, failed, skipped


def blender_name(label):
    return "3.4.1 (Debian blender)" if BPY_PINS[label] is None else f"{BPY_PINS[label]} (bpy)"


def plan(label, named, full):
    """(the test files one Blender runs, which rule chose them): the files named, else every
    test_*.py (a FULL Blender, or --full), else SUBSET; never a WINDOWED file under bpy."""
    if named:
        files, why = named, "as named"
    elif full or label in FULL:
        files, why = sorted(glob.glob(os.path.join(HERE, "test_*.py"))), "every test_*.py"
    else:
        why = "SUBSET"
        files = [os.path.join(HERE, f) for f in SUBSET]
        missing = [f for f in files if not os.path.exists(f)]
        if missing:
            raise SystemExit(f"run.py: SUBSET names {', '.join(map(os.path.basename, missing))}, "
                             f"not in {HERE}; update SUBSET in {__file__}")
    if BPY_PINS[label] is not None:  # bpy has no window; the UI test runs in the packaged Blender
        kept = [f for f in files if os.path.basename(f) not in WINDOWED]
        if len(kept) < len(files):
            why += f", not {' '.join(sorted(WINDOWED))} (no window)"
        files = kept
        if not named:
            kept = [f for f in files if os.path.basename(f) not in ONE_BLENDER]
            if len(kept) < len(files):
                why += f", not {' '.join(sorted(ONE_BLENDER))} (3.4 runs it)"
            files = kept
    return files, why


def print_list(plans):
    """--list: per Blender, the files it would run (nothing runs)."""
    for label, (files, why) in plans.items():
        py = "3.11 (Debian's)" if BPY_PINS[label] is None else pythons.cpython_of_blender(label)
        print(f"Blender {label}: {blender_name(label)}, CPython {py}: {len(files)} files ({why})")
        for f in files:
            print(f"  {os.path.relpath(f)}")


def main(argv):
    args_, names = (argv[:argv.index("--")], argv[argv.index("--") + 1:]) if "--" in argv \
        else (argv, [])
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--blender", default="3.4", choices=[*BPY_PINS, "all"])
    ap.add_argument("--setup", choices=[*BPY_PINS, "all"],
                    help="create the venv(s) of the bpy Blender(s) and stop")
    ap.add_argument("--script", help="run this script (an example, a benchmark) in the Blender "
                    "given by --blender, passing the arguments after --, and exit with its code")
    ap.add_argument("--list", action="store_true",
                    help="print which test files each Blender would run, and stop")
    ap.add_argument("--full", action="store_true",
                    help="every test_*.py in every Blender asked for, not SUBSET in 4.2-5.0")
    ap.add_argument("files", nargs="*", help="test files (default: every blender_tests/test_*.py "
                    f"in {' and '.join(sorted(FULL))}, SUBSET in the others)")
    a = ap.parse_args(args_)
    if a.setup:
        for label in (BPY_PINS if a.setup == "all" else [a.setup]):
            setup(label)
        return 0
    labels = list(BPY_PINS) if a.blender == "all" else [a.blender]
    if a.script:
        return max(subprocess.run(command(label, os.path.abspath(a.script), names),
                                  env=clean_env()).returncode for label in labels)
    named = [f if os.path.exists(f) else os.path.join(HERE, f) for f in a.files]
    plans = {label: plan(label, named, a.full) for label in labels}
    if a.list:
        print_list(plans)
        return 0
    for label in labels:  # a missing venv (or CPython 3.13) stops the run before it starts
        if BPY_PINS[label] is not None and plans[label][0]:
            require_venv(label)
    totals = {}
    for label in labels:
        p = f = k = 0
        bad = []
        for path in plans[label][0]:
            dp, df, dk = run_file(label, path, names)
            p, f, k = p + dp, f + df, k + dk
            if df:
                bad.append(os.path.basename(path))
        totals[label] = (p, f, k, len(plans[label][0]), bad)
    print("== Blender tests")
    for label, (p, f, k, _, _) in totals.items():
        print(f"Blender {blender_name(label)}: {p} passed, {f} failed, {k} skipped")
    tp, tf, tk = (sum(v[i] for v in totals.values()) for i in range(3))
    print(f"all Blenders: {tp} passed, {tf} failed, {tk} skipped")
    print(f"{'Blender':<24} {'files':>5} {'passed':>6} {'failed':>6} {'skipped':>7}  failing files")
    for label, (p, f, k, n, bad) in totals.items():
        print(f"{blender_name(label):<24} {n:>5} {p:>6} {f:>6} {k:>7}  {' '.join(bad) or '-'}")
    return 0 if tf == 0 and tp > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

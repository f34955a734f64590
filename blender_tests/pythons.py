#!/usr/bin/env python3
"""Which CPython each Blender needs, and where to find it on this machine.

Blender 4.2 to 5.0 bundle CPython 3.11 (their ``bpy`` wheels are cp311): Debian 12's
/usr/bin/python3, the interpreter the _native module is built for. Blender 5.1 and newer bundle
CPython 3.13 (cp313 wheels), which Debian 12 has not; it is looked for, in this order, at
$PLUME_PYTHON313, among pyenv's versions (the newest 3.13.x) and as ``python3.13`` on PATH, and
each candidate is run to check that it is 3.13.

    python3 blender_tests/pythons.py 3.13     # prints the path; exit 2 and why on stderr if none

Standard library only: .ci/ shell scripts run it with /usr/bin/python3."""

import os
import re
import shutil
import subprocess
import sys

#: Debian 12's CPython 3.11, the venvs of Blender 4.2 to 5.0 (and the _native module's ABI).
DEBIAN_PYTHON = "/usr/bin/python3"
#: The variable that names a CPython 3.13 explicitly.
ENV_313 = "PLUME_PYTHON313"


class PythonNotFound(RuntimeError):
    """No CPython of the version asked for; the message says what was searched and what to do."""


def cpython_of_blender(label):
    """The CPython minor ("3.11", "3.13") a Blender "x.y" runs: 3.13 from Blender 5.1 on."""
    major, minor = (int(p) for p in label.split(".")[:2])
    return "3.13" if (major, minor) >= (5, 1) else "3.11"


def _probe(path):
    """(major, minor) and the real executable of the interpreter at `path` (a pyenv shim resolves
    to the version it runs), or None when it does not run."""
    try:
        out = subprocess.run([path, "-c", "import sys;print(sys.version_info[:2]);"
                              "print(sys.executable)"], capture_output=True, text=True,
                             timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    lines = out.stdout.splitlines()
    m = re.fullmatch(r"\((\d+), (\d+)\)", lines[0].strip()) if lines else None
    if out.returncode != 0 or not m or len(lines) < 2:
        return None
    return (int(m[1]), int(m[2])), lines[1].strip() or path


def _pyenv():
    """The pyenv executable: on PATH, else $PYENV_ROOT/bin/pyenv, else ~/.pyenv/bin/pyenv."""
    found = shutil.which("pyenv")
    if found:
        return found
    for root in (os.environ.get("PYENV_ROOT"), os.path.expanduser("~/.pyenv")):
        if root and os.access(os.path.join(root, "bin", "pyenv"), os.X_OK):
            return os.path.join(root, "bin", "pyenv")
    return None


def _pyenv_candidate(minor, searched):
    """bin/python<minor> of pyenv's newest <minor>.N version, or None; notes what it did."""
    pyenv = _pyenv()
    if pyenv is None:
        searched.append("pyenv (not installed: not on PATH, nor at $PYENV_ROOT/bin or "
                        "~/.pyenv/bin)")
        return None
    try:
        bare = subprocess.run([pyenv, "versions", "--bare"], capture_output=True, text=True,
                              timeout=60).stdout.split()
    except (OSError, subprocess.TimeoutExpired):
        bare = []
    # Plain releases only: not 3.13.0t (free-threaded), 3.13-dev, nor virtualenvs (x/envs/y).
    patches = [int(v.rsplit(".", 1)[1]) for v in bare
               if re.fullmatch(re.escape(minor) + r"\.\d+", v)]
    if not patches:
        searched.append(f"`{pyenv} versions --bare` (no {minor}.x among {' '.join(bare) or '-'})")
        return None
    version = f"{minor}.{max(patches)}"
    try:
        prefix = subprocess.run([pyenv, "prefix", version], capture_output=True, text=True,
                                timeout=60).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        prefix = ""
    searched.append(f"pyenv {version} ({prefix or 'no prefix'})")
    return os.path.join(prefix, "bin", f"python{minor}") if prefix else None


def locate(minor):
    """(path, how it was found) of a CPython `minor` ("3.11" or "3.13"); raises PythonNotFound."""
    want = tuple(int(p) for p in minor.split("."))
    if minor == "3.11":
        got = _probe(DEBIAN_PYTHON)
        if got and got[0] == want:
            return DEBIAN_PYTHON, "Debian's python3"
        raise PythonNotFound(
            f"Blender 4.2 to 5.0 bundle CPython 3.11, and their bpy venvs are made from "
            f"{DEBIAN_PYTHON}, the interpreter Plume's _native module is built for; it is "
            f"{'missing' if got is None else 'CPython %d.%d' % got[0]} here (Debian 12's "
            f"python3 is 3.11).")
    if minor != "3.13":
        raise PythonNotFound(f"no Blender Plume supports needs CPython {minor} (3.11 or 3.13)")
    searched = []
    explicit = os.environ.get(ENV_313)
    if explicit:
        got = _probe(explicit)
        if got and got[0] == want:
            return got[1], f"${ENV_313}"
        raise PythonNotFound(
            f"${ENV_313} is {explicit}, which "
            f"{'does not run' if got is None else 'is CPython %d.%d' % got[0]}; Blender 5.1 and "
            f"newer bundle CPython 3.13 and their bpy wheels install only into a 3.13: point "
            f"${ENV_313} at a python3.13 executable, or unset it to search pyenv and PATH.")
    searched.append(f"${ENV_313} (not set)")
    candidate = _pyenv_candidate(minor, searched)
    for how in ("pyenv", "python3.13 on PATH"):
        if how != "pyenv":
            candidate = shutil.which("python3.13")
            searched.append(f"python3.13 on PATH ({candidate or 'none'})")
        if candidate:
            got = _probe(candidate)
            if got and got[0] == want:
                return got[1], how
            searched[-1] += " does not run" if got is None else " is CPython %d.%d" % got[0]
    raise PythonNotFound(
        "Blender 5.1 and newer bundle CPython 3.13, and their bpy wheels (cp313) install only "
        "into a CPython 3.13 venv, but none was found. Searched: " + "; ".join(searched) +
        f". Install one (e.g. `pyenv install 3.13`) or set {ENV_313}=/path/to/python3.13.")


def python_for(minor):
    """The path of a CPython `minor` ("3.11", "3.13"); raises PythonNotFound saying why not."""
    return locate(minor)[0]


def python313():
    """The path of a CPython 3.13 (Blender 5.1+); raises PythonNotFound saying why not."""
    return python_for("3.13")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(f"usage: {sys.argv[0]} 3.11|3.13   (prints that CPython's path)")
    try:
        print(python_for(sys.argv[1]))
    except PythonNotFound as e:
        print(f"pythons.py: {e}", file=sys.stderr)
        sys.exit(2)

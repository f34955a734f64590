"""The one import of the native module ``_native`` (the C++ core, one file per CPython beside
this file: ``_native.cpython-311-x86_64-linux-gnu.so``, ``_native.cpython-313-…``). Python picks
the file built for itself by its name; nothing here checks versions before trying.

When the import fails, the message says why in an artist's words: no module for this Blender's
Python (naming it and the Pythons, so the Blenders, that Plume ships for), a module that would
not load (a damaged or incomplete install), or a developer checkout without a build."""

import glob
import os
import re
import sys

#: CPython minor version -> the Blender releases that bundle it (Debian's 3.4.1 runs 3.11).
BLENDERS_OF_PYTHON = {(3, 11): "Blender 3.4 (Debian) and 4.2 to 5.0", (3, 13): "Blender 5.1 to 5.3"}


def _pythons(names):
    """The (major, minor) of every _native.cpython-3XY*.so among file names, sorted."""
    found = set()
    for name in names:
        m = re.match(r"_native\.cpython-3(\d+)", os.path.basename(name))
        if m:
            found.add((3, int(m.group(1))))
    return sorted(found)


def _build_info(folder):
    """(release, module files) from the zip's PLUME_BUILD.txt (its "plume <version>" and
    "module: …" lines), or (None, None) when the add-on was not installed from a zip (a
    developer checkout has no such file)."""
    try:
        with open(os.path.join(folder, "PLUME_BUILD.txt"), encoding="utf-8") as f:
            lines = f.read().splitlines()
    except OSError:
        return None, None
    release = next((line.split()[1] for line in lines if line.startswith("plume ")
                    and len(line.split()) == 2), "<version>")
    return release, [line.split(":", 1)[1].strip() for line in lines
                     if line.startswith("module:")]


def explain_import_failure(folder, error, python=None):
    """The message of a failed ``_native`` import: which Python this Blender runs, which ones
    Plume holds modules for, and what to do. ``python`` (major, minor) defaults to this one."""
    python = tuple(python or sys.version_info[:2])
    mine = f"Python {python[0]}.{python[1]}"
    present = _pythons(glob.glob(os.path.join(folder, "_native*.so")))
    release, listed = _build_info(folder)
    shipped = _pythons(listed) if listed is not None else present
    reinstall = (f"install plume-{release}-linux-x64.zip again (Edit › Preferences › Get "
                 "Extensions › Install from Disk; in Blender 3.4 Edit › Preferences › Add-ons › "
                 "Install…)")
    if shipped and python not in shipped:
        supported = "; ".join(f"Python {a}.{b} ({BLENDERS_OF_PYTHON.get((a, b), 'Blender ?')})"
                              for a, b in shipped)
        return (f"Plume: this Blender runs {mine}, and Plume's native module is built only for "
                f"{supported}. Use one of those Blenders, or a Plume release made for {mine}")
    if python not in present:
        if listed is not None:
            missing = [n for n in listed if _pythons([n]) == [python]]
            return (f"Plume: the installed Plume is incomplete: {', '.join(missing)} (the "
                    f"native module for this Blender's {mine}) is missing from {folder}; "
                    f"{reinstall}")
        return (f"Plume: the native module _native is missing (no _native*.so for {mine} in "
                f"{folder}); build it with: cmake -S . -B build "
                "-DPython_EXECUTABLE=/usr/bin/python3 && cmake --build build -j2 --target "
                "_native, then copy build/native/_native*.so next to the add-on's __init__.py "
                "(the README's install command does both)")
    fix = reinstall if listed is not None else "rebuild it (see native/README.md)"
    return f"Plume: the native module for {mine} is here but cannot be loaded ({error}); {fix}"


try:
    from . import _native  # noqa: F401
except ImportError as e:
    # name=: Blender 4.2+ reports an ImportError by its module name (without one it fails itself)
    raise ImportError(explain_import_failure(os.path.dirname(os.path.abspath(__file__)), e),
                      name=__package__) from e

__all__ = ["_native"]

"""The one import of the native module ``_native`` (the C++ core built by CMake and copied beside
this file). Every other module takes it from here: ``from .native import _native``.

A missing or unloadable module fails the add-on's import with a message that says how to build
or reinstall it."""

try:
    from . import _native  # noqa: F401
except ImportError as e:
    import glob
    import os
    _here = os.path.dirname(os.path.abspath(__file__))
    _why = (f"cannot be loaded ({e})" if glob.glob(os.path.join(_here, "_native*.so"))
            else f"is missing (no _native*.so in {_here})")
    if os.path.isdir(os.path.join(_here, "lib")):  # installed from the zip, libraries bundled
        _fix = ("A library bundled with Plume is missing or damaged (named above): install "
                "plume-<version>-linux-x64.zip again")
    else:
        _fix = ("Build it with: cmake -S . -B build -DPython_EXECUTABLE=/usr/bin/python3 && "
                "cmake --build build -j2 --target _native, then copy build/native/_native*.so "
                "next to the add-on's __init__.py (the README's install command does both)")
    # name=: Blender 4.2+ reports an ImportError by its module name (without one it fails itself)
    raise ImportError(f"Plume: the native module _native {_why}. {_fix}",
                      name=__package__) from e

__all__ = ["_native"]

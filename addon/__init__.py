"""Plume: small-scale smoke and fire for Blender, backed by the native module ``_native``.

Installed as the package ``plume`` with ``_native.cpython-311-x86_64-linux-gnu.so`` beside this
file. Only relative imports, so it also loads as a Blender 4.2+ extension (``bl_ext.*.plume``)."""

import sys

bl_info = {
    "name": "Plume",
    "author": "Plume developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Physics",
    "description": "Smoke and fire simulation with streak surfaces, toon smoke, graph fire "
                   "and structural flames",
    "category": "Physics",
}
#: "0.1.0": kept apart from bl_info, which Blender 4.2+ deletes from an extension's module.
VERSION = ".".join(str(v) for v in bl_info["version"])

if sys.version_info[:2] != (3, 11):
    raise ImportError(
        "Plume: the native module is built for Python 3.11, but this Blender runs Python "
        f"{sys.version_info[0]}.{sys.version_info[1]}; use Blender 3.4 to 5.0 (Python 3.11) "
        "or rebuild the module against this Python", name=__name__)

import bpy  # noqa: E402

if tuple(bpy.app.version) < (3, 4, 0):
    raise ImportError(f"Plume needs Blender 3.4 or newer (this is {bpy.app.version_string}); "
                      "tested in 3.4.1, 4.5 LTS and 5.0", name=__name__)

try:
    from . import _native  # noqa: F401  (fail here, with a clear message)
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
    raise ImportError(f"Plume: the native module _native {_why}. {_fix}", name=__name__) from e

from . import jobs, operators, properties, ui  # noqa: E402
from .build import surfaces as _surfaces  # noqa: E402
from .build import toon_points as _toon_points  # noqa: E402
from .build import fire_points as _fire_points  # noqa: E402
from .build import flame_spines as _flame_spines  # noqa: E402

_classes = operators.classes + ui.classes


def register():
    properties.register()
    for cls in _classes:
        bpy.utils.register_class(cls)
    _surfaces.register()  # persistent frame_change_pre handler of the streak surfaces
    _toon_points.register()  # persistent frame_change_pre handler of the toon points
    _fire_points.register()  # persistent frame_change_pre handler of the fire point preview
    _flame_spines.register()  # persistent frame_change_pre handler of flame spines and lights
    jobs.register()  # persistent load_pre + atexit: loading a file or quitting cancels the jobs


def unregister():
    jobs.unregister()  # running jobs are cancelled first, their temporaries removed
    _flame_spines.unregister()
    _fire_points.unregister()
    _toon_points.unregister()
    _surfaces.unregister()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
    properties.unregister()

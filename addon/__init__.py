"""Plume: small-scale smoke and fire for Blender, backed by the native module ``_native``.

Installed as the package ``plume`` with one native module per CPython beside this file
(``_native.cpython-311-x86_64-linux-gnu.so`` for Blender 3.4-5.0, ``…-313-…`` for 5.1+): Python
picks the one built for itself by its file name, and ``native.py`` explains a Python with none.
Only relative imports, so it also loads as a Blender 4.2+ extension (``bl_ext.*.plume``)."""

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

import bpy  # noqa: E402

if tuple(bpy.app.version) < (3, 4, 0):
    raise ImportError(f"Plume needs Blender 3.4 or newer (this is {bpy.app.version_string}); "
                      "tested in 3.4.1 and 4.2 LTS to 5.3", name=__name__)

from . import native  # noqa: E402,F401  (fails here, with a clear message)
from . import cache_state, jobs, operators, properties, ui  # noqa: E402
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
    cache_state.register()  # the panels' cache state: read when a job ends or a file loads


def unregister():
    cache_state.unregister()
    jobs.unregister()  # running jobs are cancelled first, their temporaries removed
    _flame_spines.unregister()
    _fire_points.unregister()
    _toon_points.unregister()
    _surfaces.unregister()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
    properties.unregister()

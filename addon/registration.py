"""Blender's side of the add-on: the classes, handlers and properties register() adds."""

import bpy

if tuple(bpy.app.version) < (3, 4, 0):
    raise ImportError(f"Plume needs Blender 3.4 or newer (this is {bpy.app.version_string}); "
                      "tested in 3.4.1 and 4.2 LTS to 5.3", name=__name__)

from . import native  # noqa: E402,F401  (fails here, with a clear message)
from . import cache_state, manual, operators, preferences, properties, ui  # noqa: E402
from .jobs import handlers as _job_handlers  # noqa: E402
from .build import surfaces as _surfaces  # noqa: E402
from .build import toon_points as _toon_points  # noqa: E402
from .build import fire_points as _fire_points  # noqa: E402
from .build import flame_spines as _flame_spines  # noqa: E402

_classes = operators.classes + ui.classes + preferences.classes


def register():
    properties.register()
    for cls in _classes:
        bpy.utils.register_class(cls)
    _surfaces.register()  # persistent frame_change_pre handler of the streak surfaces
    _toon_points.register()  # persistent frame_change_pre handler of the toon points
    _fire_points.register()  # persistent frame_change_pre handler of the fire point preview
    _flame_spines.register()  # persistent frame_change_pre handler of flame spines and lights
    _job_handlers.register()  # persistent load_pre + atexit: a file load or quit ends the jobs
    cache_state.register()  # the panels' cache state: read when a job ends or a file loads
    bpy.utils.register_manual_map(manual.manual_map)  # right click › Online Manual


def unregister():
    bpy.utils.unregister_manual_map(manual.manual_map)
    cache_state.unregister()
    _job_handlers.unregister()  # running jobs end first, their temporaries removed
    _flame_spines.unregister()
    _fire_points.unregister()
    _toon_points.unregister()
    _surfaces.unregister()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
    properties.unregister()

"""Adding and removing the persistent frame_change_pre handlers that move built objects (streak
surfaces, toon points, fire point preview) to the cached data of each frame, once each however
often the add-on is enabled."""

import bpy


def add(handler):
    if handler not in bpy.app.handlers.frame_change_pre:
        bpy.app.handlers.frame_change_pre.append(handler)


def remove(handler):
    while handler in bpy.app.handlers.frame_change_pre:
        bpy.app.handlers.frame_change_pre.remove(handler)

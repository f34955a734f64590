"""Panels of the Physics tab (draw() never reads the disk: cache_state holds what they show)."""

from . import flame_panels, panels

classes = panels.classes + flame_panels.classes

"""Panels of the Physics tab, and of a built smoke sheet (draw() never reads the disk:
cache_state holds what they show)."""

from . import flame_panels, panels, sheet_panels

classes = panels.classes + flame_panels.classes + sheet_panels.classes

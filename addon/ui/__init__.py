"""Panels of the Physics tab, of a built smoke sheet and of the farm (Scene tab) (draw() never reads the disk:
cache_state holds what they show)."""

from . import farm_panel, flame_panels, panels, sheet_panels

classes = panels.classes + flame_panels.classes + sheet_panels.classes + farm_panel.classes

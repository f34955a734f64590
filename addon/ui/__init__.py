"""Panels of the Physics tab."""

from . import flame_panels, panels

classes = panels.classes + flame_panels.classes

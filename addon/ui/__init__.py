"""Panels of the Physics tab."""

from .panels import classes  # noqa: F401

"""Operators: plume.role_set, plume.bake, plume.cache_free, plume.surfaces_build."""

from . import bake, roles, surfaces

classes = roles.classes + bake.classes + surfaces.classes

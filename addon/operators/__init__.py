"""Operators: plume.role_set, plume.bake, plume.cache_free."""

from . import bake, roles

classes = roles.classes + bake.classes

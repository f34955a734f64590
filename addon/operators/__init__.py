"""Operators: plume.role_set, plume.bake, plume.cache_free, plume.surfaces_build, and on built
surfaces plume.surface_edits_store / _clear, plume.surfaces_bake_keyframes,
plume.surfaces_export_mesh; plume.toon_build; plume.flowgraph_build, plume.fire_synthesize; plume.flames_bake,
plume.flames_free; plume.flame_preset, plume.flames_auto_exposure; plume.manual_open; plume.farm_submit / _refresh / _resubmit / _cancel."""

from . import (bake, farm, flame_look, flames, flowgraph, manual_open, roles, surface_edits,
               surfaces, toon)

classes = (roles.classes + bake.classes + surfaces.classes + surface_edits.classes + toon.classes
           + flowgraph.classes + flames.classes + flame_look.classes + manual_open.classes
           + farm.classes)

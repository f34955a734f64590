"""Object and scene properties: ``obj.plume`` with ``role``, ``domain``, ``source``, ``obstacle``
and ``flame``, and ``scene.plume_flames``; one module per pipeline (domain: a domain's grid bake
with its streak and pathline settings; source: Sources and Obstacles; toon; flowgraph; flames;
farm: ``scene.plume_farm``).

Numbers carry soft limits only: a script may set any value, and the bake validates it with a
message naming the setting instead of Blender clamping it silently. Validated bounds come from
ranges.py, like the validation's."""

import bpy
from bpy.props import EnumProperty, PointerProperty

from .domain import PlumeDomainSettings
from .farm import PlumeFarmSettings
from .flames import PlumeFlameSourceSettings, PlumeFlamesSettings
from .flowgraph import PlumeFlowGraphSettings
from .source import PlumeObstacleSettings, PlumeSourceSettings
from .toon import PlumeToonSettings

ROLE_ITEMS = (
    ('NONE', "None", "Not part of a Plume simulation", 'X', 0),
    ('DOMAIN', "Domain", "Box holding the smoke simulation grid", 'MESH_CUBE', 1),
    ('SOURCE', "Source", "Emits smoke (density, heat, fuel) into the domain", 'OUTLINER_OB_FORCE_FIELD', 2),
    ('OBSTACLE', "Obstacle", "Closed mesh the smoke flows around", 'MOD_PHYSICS', 3),
    ('FLAME_SOURCE', "Flame Source", "Emits structural flames (Bake Flames)", 'LIGHT_SUN', 4),
)


class PlumeObjectSettings(bpy.types.PropertyGroup):
    role: EnumProperty(name="Role", items=ROLE_ITEMS, default='NONE',
                       description="What this object is in a Plume simulation")
    domain: PointerProperty(type=PlumeDomainSettings)
    source: PointerProperty(type=PlumeSourceSettings)
    obstacle: PointerProperty(type=PlumeObstacleSettings)
    flame: PointerProperty(type=PlumeFlameSourceSettings)  # role FLAME_SOURCE


classes = (PlumeFlameSourceSettings, PlumeFlamesSettings, PlumeToonSettings,
           PlumeFlowGraphSettings, PlumeDomainSettings, PlumeSourceSettings,
           PlumeObstacleSettings, PlumeObjectSettings, PlumeFarmSettings)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Object.plume = PointerProperty(type=PlumeObjectSettings, name="Plume")
    bpy.types.Scene.plume_flames = PointerProperty(type=PlumeFlamesSettings, name="Plume Flames")
    bpy.types.Scene.plume_farm = PointerProperty(type=PlumeFarmSettings, name="Plume Farm")


def unregister():
    del bpy.types.Scene.plume_farm
    del bpy.types.Scene.plume_flames
    del bpy.types.Object.plume
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)

"""Physics tab panels of structural flames (structural_flames.txt): "Flame Source" on a
FLAME_SOURCE object (obj.plume.flame) and "Flames" (scene.plume_flames, Bake / Free), the same
scene settings also in the Scene tab."""

import bpy

from .panels import PlumePanel
from ..operators.flames import is_baking


class FlameSourcePanel(PlumePanel):
    """A sub-panel of "Plume" shown on Flame Sources."""

    bl_parent_id = "PHYSICS_PT_plume"

    @classmethod
    def poll(cls, context):
        p = cls.plume(context)
        return p is not None and p.role == 'FLAME_SOURCE'


class PHYSICS_PT_plume_flame_source(FlameSourcePanel, bpy.types.Panel):
    bl_label = "Flame Source"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        fl = context.object.plume.flame
        layout.prop(fl, "profile")
        sub = layout.column()
        sub.active = fl.profile == 'CUSTOM'
        sub.prop(fl, "profile_curve")
        layout.prop(fl, "color_source")
        if fl.color_source == 'IMAGE':
            layout.prop(fl, "color_image")
        for name in ("flames", "radius", "intensity", "temperature"):
            layout.prop(fl, name)
        col = layout.column(heading="Spread")
        col.prop(fl, "spread")
        if fl.spread == 'MAPS':
            for name in ("activation_map", "time_scale", "duration_map", "duration_scale",
                         "intensity_map", "diameter_map", "height_map"):
                col.prop(fl, name)
        elif fl.spread == 'MODEL':
            for name in ("ignition", "spread_temperature", "spread_thickness"):
                col.prop(fl, name)


def draw_flames(layout, scene):
    """The scene's flame settings and the Bake / Free buttons."""
    layout.use_property_split = True
    f = scene.plume_flames
    row = layout.row(align=True)
    row.enabled = not is_baking()
    row.operator("plume.flames_bake", icon='PHYSICS')
    row.operator("plume.flames_free", icon='TRASH')
    layout.operator("plume.flames_bake_spines_keyframes", icon='KEYINGSET')
    col = layout.column(align=True)
    col.prop(f, "frame_start", text="Frame Start")
    col.prop(f, "frame_end", text="End")
    for name in ("seed", "substeps"):
        layout.prop(f, name)
    col = layout.column(heading="Structure", align=True)
    for name in ("points", "height_persistent", "height_intermittent", "height_max",
                 "lifespan_scale", "breakaway_frequency", "buoyancy", "diffusion"):
        col.prop(f, name)
    col = layout.column(heading="Shape", align=True)
    for name in ("particles_per_pixel", "max_particles", "merging", "flow_noise", "kolmogorov"):
        col.prop(f, name)
    col = layout.column(heading="Wind", align=True)
    for name in ("wind", "use_force_fields", "wind_domain", "use_obstacles"):
        col.prop(f, name)
    col = layout.column(heading="Render", align=True)
    for name in ("voxel_size", "temperature_scale", "emission", "opacity", "heat_of_combustion",
                 "light_unit", "lights", "cache_directory"):
        col.prop(f, name)
    if f.summary:
        layout.label(text=f.summary, icon='INFO')


class PHYSICS_PT_plume_flames(FlameSourcePanel, bpy.types.Panel):
    bl_label = "Flames"

    def draw(self, context):
        draw_flames(self.layout, context.scene)


class SCENE_PT_plume_flames(bpy.types.Panel):
    bl_label = "Plume Flames"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "scene"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        draw_flames(self.layout, context.scene)


classes = (PHYSICS_PT_plume_flame_source, PHYSICS_PT_plume_flames, SCENE_PT_plume_flames)

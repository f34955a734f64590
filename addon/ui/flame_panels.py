"""Physics tab panels of structural flames ([Structural Flames]): "Flame Source" on a
FLAME_SOURCE object (obj.plume.flame) and "Flames" (scene.plume_flames, Bake / Free), the same
scene settings also in the Scene tab."""

import bpy

from .panels import PlumePanel
from .. import manual
from ..operators.manual_open import draw_help
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
        layout.operator_menu_enum("plume.flame_preset", "preset", text="Preset", icon='PRESET')
        layout.prop(fl, "profile")
        sub = layout.column()
        sub.active = fl.profile == 'CUSTOM'
        sub.prop(fl, "profile_curve")
        layout.prop(fl, "color_source")
        if fl.color_source == 'IMAGE':
            layout.prop(fl, "color_image")
        for name in ("flames", "radius", "stops", "intensity", "temperature"):
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
    layout.operator("plume.flames_auto_exposure", icon='LIGHT_SUN')
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
    for name in ("particles_per_pixel", "max_particles", "merging"):
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


#: The "Noise" sub-panel: (heading, settings) per noise.
NOISE_GROUPS = (
    ("Spine (§4.2)", ("spine_noise", "spine_noise_scale", "spine_noise_frequency",
                      "spine_noise_drift")),
    ("Flow (§4.5)", ("flow_noise", "flow_noise_scale", "flow_noise_frequency",
                     "flow_noise_rotation")),
    ("Kolmogorov (§4.5)", ("kolmogorov", "kolmogorov_scale", "kolmogorov_frequency",
                           "kolmogorov_drift")),
)


def draw_flame_noise(layout, scene):
    """The three noises: Kolmogorov velocity on the spines' control points (§4.2), flow noise
    and Kolmogorov displacement of the render particles (§4.5)."""
    layout.use_property_split = True
    f = scene.plume_flames
    for heading, names in NOISE_GROUPS:
        col = layout.column(heading=heading, align=True)
        for name in names:
            col.prop(f, name)


class PHYSICS_PT_plume_flames(FlameSourcePanel, bpy.types.Panel):
    bl_label = "Flames"

    def draw(self, context):
        draw_flames(self.layout, context.scene)


class PHYSICS_PT_plume_flames_noise(FlameSourcePanel, bpy.types.Panel):
    bl_label = "Noise"
    bl_parent_id = "PHYSICS_PT_plume_flames"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        draw_flame_noise(self.layout, context.scene)


class SCENE_PT_plume_flames(bpy.types.Panel):
    bl_label = "Plume Flames"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "scene"
    bl_options = {'DEFAULT_CLOSED'}

    def draw_header_preset(self, context):
        draw_help(self.layout, manual.FLAMES)

    def draw(self, context):
        draw_flames(self.layout, context.scene)


class SCENE_PT_plume_flames_noise(bpy.types.Panel):
    bl_label = "Noise"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "scene"
    bl_parent_id = "SCENE_PT_plume_flames"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        draw_flame_noise(self.layout, context.scene)


classes = (PHYSICS_PT_plume_flame_source, PHYSICS_PT_plume_flames,
           PHYSICS_PT_plume_flames_noise, SCENE_PT_plume_flames, SCENE_PT_plume_flames_noise)

"""Properties editor > Physics tab: the "Plume" panel and its sub-panels (laid out like
Mantaflow's): role buttons, then the settings of the object's role."""

import bpy

from .. import streak_count
from ..fuel_warning import fuel_without_combustion
from ..native import _native
from ..operators.bake import is_baking, is_busy
from .. import cache_state
from ..operators import surfaces
from ..properties import ROLE_ITEMS
from .sheet_panels import draw_sheet_buttons
from .. import manual
from ..operators.manual_open import draw_help


class PlumePanel:
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "physics"

    @staticmethod
    def plume(context):
        ob = context.object
        return None if ob is None else ob.plume


class PlumeDomainPanel(PlumePanel):
    bl_parent_id = "PHYSICS_PT_plume"
    #: The manual section the header's Help button (?) opens; None for no button.
    manual_page = None

    def draw_header_preset(self, context):
        if self.manual_page:
            draw_help(self.layout, self.manual_page)

    @classmethod
    def poll(cls, context):
        p = cls.plume(context)
        return p is not None and p.role == 'DOMAIN'


class PHYSICS_PT_plume(PlumePanel, bpy.types.Panel):
    bl_label = "Plume"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == 'MESH'

    def draw_header_preset(self, context):
        role = context.object.plume.role
        draw_help(self.layout, {'NONE': manual.INDEX, 'FLAME_SOURCE': manual.FLAMES}.get(
            role, manual.SMOKE_USE))

    def draw(self, context):
        layout = self.layout
        p = context.object.plume
        grid = layout.grid_flow(row_major=True, columns=3, even_columns=True, align=True)
        for ident, name, _desc, icon, _num in ROLE_ITEMS:
            op = grid.operator("plume.role_set", text=name, icon=icon, depress=(p.role == ident))
            op.role = ident
        if p.role == 'DOMAIN':
            row = layout.row(align=True)
            row.enabled = not is_busy(context.object)
            row.operator("plume.bake", icon='PHYSICS')
            row.operator("plume.cache_free", icon='TRASH')


class PHYSICS_PT_plume_settings(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Settings"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        d = context.object.plume.domain
        layout.prop(d, "resolution")
        col = layout.column(align=True)
        col.prop(d, "frame_start", text="Frame Start")
        col.prop(d, "frame_end", text="End")
        layout.prop(d, "time_scale")
        col = layout.column(align=True)
        col.prop(d, "substeps")
        col.prop(d, "use_cfl")
        sub = col.row()
        sub.active = d.use_cfl
        sub.prop(d, "cfl")
        layout.prop(d, "seed")
        layout.prop(d, "threads")
        col = layout.column(align=True)
        col.prop(d, "adaptive_domain")
        sub = col.column(align=True)
        sub.active = d.adaptive_domain
        sub.prop(d, "adaptive_margin")
        sub.prop(d, "adaptive_threshold")


class PHYSICS_PT_plume_forces(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Forces"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        d = context.object.plume.domain
        col = layout.column(align=True)
        col.prop(d, "alpha")
        col.prop(d, "beta")
        col.prop(d, "buoyancy_units")
        col.prop(d, "ambient_temperature")
        layout.prop(d, "gravity")
        layout.prop(d, "vorticity")
        layout.prop(d, "wind")
        layout.prop(d, "wind_strength")
        col = layout.column(align=True)
        col.prop(d, "turbulence")
        col.prop(d, "turbulence_scale", text="Size")
        col.prop(d, "turbulence_rate", text="Speed")
        layout.prop(d, "density_dissipation")


class PHYSICS_PT_plume_advection(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Advection"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        d = context.object.plume.domain
        layout.prop(d, "advection")
        layout.prop(d, "interpolation")
        layout.prop(d, "linear_velocity")
        layout.prop(d, "trace")
        layout.prop(d, "conserve_mass")


class PHYSICS_PT_plume_pressure(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Pressure"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        d = context.object.plume.domain
        layout.prop(d, "pressure_tolerance")
        layout.prop(d, "max_pressure_iterations")


class PHYSICS_PT_plume_boundaries(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Boundaries"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        d = context.object.plume.domain
        for side in ("neg_x", "pos_x", "neg_y", "pos_y", "neg_z", "pos_z"):
            layout.prop(d, "boundary_" + side)


class PHYSICS_PT_plume_combustion(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Combustion"
    bl_options = {'DEFAULT_CLOSED'}

    def draw_header(self, context):
        self.layout.prop(context.object.plume.domain, "combustion", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        d = context.object.plume.domain
        layout.active = d.combustion
        for name in ("burn_rate", "soot_yield", "heat_yield", "conductivity", "cooling_rate",
                     "max_temperature", "expansion", "flame_vorticity"):
            layout.prop(d, name)
        # Pathline groups for flow-graph fire ([Graph Fire Synthesis] §4.2).
        layout.prop(d, "pathlines")
        col = layout.column()
        col.active = d.pathlines
        for name in ("pathline_nodes_per_frame", "pathline_lifetime", "pathline_float16"):
            col.prop(d, name)


class PHYSICS_PT_plume_flame_smoke(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Flame Smoke"
    bl_options = {'DEFAULT_CLOSED'}

    def draw_header(self, context):
        self.layout.prop(context.object.plume.domain, "flame_smoke", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        d = context.object.plume.domain
        layout.active = d.flame_smoke
        layout.prop(d, "flame_smoke_yield")
        layout.prop(d, "flame_smoke_point")
        layout.prop(d, "flame_smoke_temperature")


class PHYSICS_PT_plume_cache(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Cache"
    manual_page = manual.SMOKE_CACHE

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        d = ob.plume.domain
        layout.prop(d, "motion_source")
        sub = layout.column()
        sub.active = d.motion_source == 'MANTAFLOW'  # its cache moves the smoke, no simulation
        sub.prop(d, "mantaflow_domain")
        layout.prop(d, "cache_directory", text="Directory")
        layout.prop(d, "velocity_everywhere")
        baking = is_baking(ob)
        row = layout.row(align=True)
        row.enabled = not is_busy(ob)
        row.operator("plume.bake", icon='PHYSICS')
        row.operator("plume.cache_free", icon='TRASH')
        done, total = cache_state.cache_status(ob)
        state = "baking" if baking else ("complete" if total and done >= total else "")
        layout.label(text=f"Frames: {done} / {total} {state}".rstrip(), icon='INFO')
        if d.volume_object:
            layout.label(text=f"Volume: {d.volume_object}", icon='OUTLINER_OB_VOLUME')


class PHYSICS_PT_plume_streaks(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Streak Surfaces"
    manual_page = manual.STREAKS_USE
    bl_options = {'DEFAULT_CLOSED'}

    def draw_header(self, context):
        self.layout.prop(context.object.plume.domain, "streaks", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        d = ob.plume.domain
        col = layout.column()
        col.active = d.streaks
        col.prop(d, "emission_period")
        col.prop(d, "max_streaklines")
        if d.streaks:  # what the next bake traces (§3.2), before baking
            col.label(text=streak_count.label(_native, context.scene, ob), icon='CURVE_PATH')
        row = col.row(align=True)
        row.prop(d, "streak_threshold")
        row.operator("plume.surfaces_pick_threshold", text="", icon='SORTSIZE')
        # Live count from the h cached by the last build (never computed here, §3.3 Figure 4).
        m = cache_state.manifest(ob)
        counts = None if m is None else surfaces.live_summary(ob, m)
        if counts is not None:
            col.label(text=f"{counts[0]} surfaces from {counts[1]} streaklines", icon='INFO')
        else:
            col.label(text="Build once to see the surface count", icon='INFO')
        sub = col.column(align=True)
        sub.prop(d, "density_k_u")
        sub.prop(d, "density_k_v")
        col.prop(d, "sheet_falloff")
        col.prop(d, "sheet_shading")
        col.prop(d, "sheet_color")
        sub = col.column()
        sub.active = d.sheet_shading == 'EMISSION'
        sub.prop(d, "sheet_brightness")
        col.prop(d, "sheet_opacity")
        row = col.row()
        row.enabled = not is_busy(ob)
        row.operator("plume.surfaces_build", icon='SURFACE_NSURFACE')
        if d.surfaces_collection:
            col.operator("plume.surfaces_fast_render", icon='RENDER_STILL')
        # On the built surfaces (all of this domain's; §5 hand edits, keyframes, mesh export).
        if d.surfaces_collection:
            draw_sheet_buttons(col)


class PHYSICS_PT_plume_toon(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Toon Smoke"
    manual_page = manual.TOON
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        t = ob.plume.domain.toon
        col = layout.column(heading="Particles")
        for name in ("emission_count", "birth_density", "birth_spacing", "death_density",
                     "max_count", "integration", "cfl", "seed"):
            col.prop(t, name)
        col = layout.column(heading="Size Ramp", align=True)
        for name in ("ramp_density_low", "ramp_density_high", "size_low", "size_high",
                     "max_size_change"):
            col.prop(t, name)
        # Stencils under a cell read as specks with outlines (§2.2): show s0, s1 in cells.
        cell = max(ob.dimensions) / max(1, ob.plume.domain.resolution)
        if cell > 0.0:
            col.label(text=f"Stencils {t.size_low / cell:.1f} to {t.size_high / cell:.1f} cells",
                      icon='INFO')
        layout.prop(t, "stretch_factor")
        col = layout.column(heading="Colour", align=True)
        for name in ("color_driver", "color_low", "color_high", "ramp_color_low",
                     "ramp_color_high"):
            col.prop(t, name)
        layout.prop(t, "stencil")
        sub = layout.column()
        sub.active = t.stencil == 'IMAGE'
        sub.prop(t, "stencil_image")
        col = layout.column(heading="Outlines")
        col.prop(t, "depth_threshold")
        col.prop(t, "outline_color")
        col.prop(t, "outline_width")
        col.prop(t, "outline_thinning")
        sub = col.column()
        sub.active = t.outline_thinning > 0.0
        sub.prop(t, "outline_thinning_distance")
        col.prop(t, "ignore_background")
        col.prop(t, "use_freestyle")
        row = layout.row()
        row.enabled = not is_busy(ob)
        row.operator("plume.toon_build", icon='MOD_PARTICLES')
        if t.object_name:
            layout.label(text=f"Toon: {t.object_name}", icon='OUTLINER_OB_POINTCLOUD')


class PHYSICS_PT_plume_flowgraph(PlumeDomainPanel, bpy.types.Panel):
    bl_label = "Flow-Graph Fire"
    manual_page = manual.FLOWGRAPH
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        ob = context.object
        g = ob.plume.domain.flowgraph
        col = layout.column(heading="Graph")
        for name in ("block_size", "epsilon", "min_node_gap", "auto_weights"):
            col.prop(g, name)
        sub = col.column(align=True)
        sub.active = not g.auto_weights
        sub.prop(g, "alpha")
        sub.prop(g, "beta")
        row = layout.row()
        row.enabled = not is_busy(context.object)
        row.operator("plume.flowgraph_build", icon='NODETREE')
        if g.summary:
            layout.label(text=g.state_names, icon='INFO')
            layout.label(text=g.summary)
            img = bpy.data.images.get("Plume Flow Graph " + ob.name)
            if img is not None and img.preview is not None:
                layout.template_icon(icon_value=img.preview.icon_id, scale=10.0)
        layout.label(text="Synthesis")
        col = layout.column(align=True)  # as the Settings panel lays out a frame range
        col.prop(g, "frame_start", text="Frame Start")
        col.prop(g, "frame_end", text="End")
        col = layout.column()
        for name in ("seed", "traversal", "gamma", "transition_hold"):
            col.prop(g, name)
        sub = col.column()
        sub.active = g.transition_hold == 'CUSTOM'
        sub.prop(g, "transition_hold_frames")
        for name in ("start_state", "target_state", "fire_source", "wind", "use_force_fields",
                     "point_preview"):
            col.prop(g, name)
        sub = col.column()
        sub.active = g.point_preview
        sub.prop(g, "preview_points")
        col.prop(g, "group_cache")
        row = layout.row()
        row.enabled = not is_busy(context.object)
        row.operator("plume.fire_synthesize", icon='PLAY')
        if g.fire_object:
            layout.label(text=f"Fire: {g.fire_object}", icon='OUTLINER_OB_VOLUME')
        if g.points_object:
            layout.label(text=f"Points: {g.points_object}", icon='OUTLINER_OB_POINTCLOUD')


def source_fuel_warning(scene, ob):
    """fuel_warning.fuel_without_combustion() of Source `ob`: its Fuel and the domains of the
    scene it feeds (every Plume domain simulating with Plume, as the bake's snapshot takes
    every Source of the scene)."""
    domains = [(o.name, o.plume.domain.combustion) for o in scene.objects
               if o.type == 'MESH' and o.plume.role == 'DOMAIN'
               and o.plume.domain.motion_source != 'MANTAFLOW']
    return fuel_without_combustion([(ob.name, ob.plume.source.fuel)], domains)


class PHYSICS_PT_plume_source(PlumePanel, bpy.types.Panel):
    bl_label = "Source"
    bl_parent_id = "PHYSICS_PT_plume"

    @classmethod
    def poll(cls, context):
        p = cls.plume(context)
        return p is not None and p.role == 'SOURCE'  # Flame Sources: flame_panels.py

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.object.plume.source
        layout.prop(s, "density")
        layout.prop(s, "temperature")
        col = layout.column(align=True)
        col.active = s.fuel <= 0.0  # a fuel source uses Flicker (below)
        col.prop(s, "smoke_noise")
        col.prop(s, "smoke_noise_scale", text="Size")
        col.prop(s, "smoke_noise_rate", text="Speed")
        layout.prop(s, "fuel")
        col = layout.column(align=True)
        col.active = s.fuel > 0.0
        col.prop(s, "fuel_noise")
        col.prop(s, "fuel_noise_scale", text="Size")
        col.prop(s, "fuel_noise_rate", text="Speed")
        warning = source_fuel_warning(context.scene, context.object)
        if warning:
            col = layout.column(align=True)
            col.alert = True
            for i, line in enumerate(warning):
                col.label(text=line, icon='ERROR' if i == 0 else 'BLANK1')
        layout.prop(s, "velocity")
        layout.prop(s, "motion_factor")
        col = layout.column(heading="Streak Surfaces")
        col.prop(s, "emit_particles")
        col.prop(s, "point_source_mesh")
        sub = col.column()
        sub.active = s.point_source_mesh is None  # the mesh's vertices replace placed points
        sub.prop(s, "point_placement")
        row = sub.row()
        row.active = s.point_placement == 'CELLS'
        row.prop(s, "point_sources")
        sub = col.column()
        sub.active = s.candidate_split <= 1  # split groups are numbered after all the others
        sub.prop(s, "candidate_group")
        col.prop(s, "candidate_split")


class PHYSICS_PT_plume_obstacle(PlumePanel, bpy.types.Panel):
    bl_label = "Obstacle"
    bl_parent_id = "PHYSICS_PT_plume"

    @classmethod
    def poll(cls, context):
        p = cls.plume(context)
        return p is not None and p.role == 'OBSTACLE'

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.prop(context.object.plume.obstacle, "slip")


classes = (
    PHYSICS_PT_plume,
    PHYSICS_PT_plume_settings,
    PHYSICS_PT_plume_forces,
    PHYSICS_PT_plume_advection,
    PHYSICS_PT_plume_pressure,
    PHYSICS_PT_plume_boundaries,
    PHYSICS_PT_plume_combustion,
    PHYSICS_PT_plume_flame_smoke,
    PHYSICS_PT_plume_cache,
    PHYSICS_PT_plume_streaks,
    PHYSICS_PT_plume_toon,
    PHYSICS_PT_plume_flowgraph,
    PHYSICS_PT_plume_source,
    PHYSICS_PT_plume_obstacle,
)

"""How the flames look: plume.flame_preset (Candle, Torch, Campfire, Dragon Breath on the active
Flame Source and the scene's Flames settings) and plume.flames_auto_exposure (meters the baked
flames once and sets Cycles' film exposure; never per render)."""

import os

import bpy
from bpy.props import EnumProperty

from .. import flame_meter, flame_presets, flames
from ..native import _native
from ..snapshot import flames_cache_folder
from ..ui_words import ADD_CAMERA, FLAMES, ui

#: Frames of the bake Auto Exposure reads (evenly spaced): the flames' level moves little
#: between neighbouring frames, and each read is one VDB grid.
METERED_FRAMES = 8


class PLUME_OT_flame_preset(bpy.types.Operator):
    """Set this Flame Source and the scene's Flames settings from a preset: its profile, size,
    flames and Intensity, and the heights, breakaway, noise and voxel size it needs (the scene's
    Flames settings are shared by every Flame Source)"""

    bl_idname = "plume.flame_preset"
    bl_label = "Flame Preset"
    bl_options = {'REGISTER', 'UNDO'}

    preset: EnumProperty(name="Preset", items=flame_presets.ITEMS,
                         description="The flame to start from")

    @classmethod
    def poll(cls, context):
        ob = context.object
        return ob is not None and getattr(ob, "plume", None) is not None and \
            ob.plume.role == 'FLAME_SOURCE'

    def execute(self, context):
        fl, f = context.object.plume.flame, context.scene.plume_flames
        for name, value in flame_presets.source_settings(self.preset).items():
            setattr(fl, name, value)
        for name, value in flame_presets.scene_settings(self.preset).items():
            setattr(f, name, value)
        label = flame_presets.PRESETS[self.preset][0]
        self.report({'INFO'}, f"Plume: {label} preset on '{context.object.name}' (and the "
                              "scene's Flames settings, shared by every Flame Source)")
        return {'FINISHED'}


def metered_levels(scene, folder, first, count, forward):
    """The flame level (flame_meter.flame_level) of up to METERED_FRAMES baked frames."""
    step = max(1, count // METERED_FRAMES)
    frames = range(first + count - 1, first - 1, -step)[:METERED_FRAMES]
    axis = flame_meter.view_axis(forward)
    levels = []
    for frame in frames:
        path = flames.volume_path(folder, frame)
        if not os.path.isfile(path):
            continue
        g = _native.read_vdb_grid(path, "emission")
        cols = flame_meter.column_brightness(g["values"], g["voxel_size"], axis,
                                             scene.plume_flames.emission)
        levels.append(flame_meter.flame_level(cols))
    return levels


class PLUME_OT_flames_auto_exposure(bpy.types.Operator):
    """Meter the baked flames as the scene camera sees them and set the film exposure once
    (Render Properties › Film › Exposure) so their bright body reads orange-yellow with a small
    white core. Run it again after a new bake or a new camera; renders never change it"""

    bl_idname = "plume.flames_auto_exposure"
    bl_label = "Auto Exposure"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        scene = context.scene
        f = scene.plume_flames
        if f.frames_baked < 1:
            self.report({'ERROR'}, "Plume: Auto Exposure meters baked flames: bake them first "
                                   f"({FLAMES} › Bake Flames)")
            return {'CANCELLED'}
        if scene.camera is None:
            self.report({'ERROR'}, "Plume: Auto Exposure meters the flames as the camera sees "
                                   f"them: {ADD_CAMERA}")
            return {'CANCELLED'}
        forward = scene.camera.matrix_world.to_3x3().col[2] * -1.0
        try:
            levels = metered_levels(scene, flames_cache_folder(scene), int(f.frame_start),
                                    int(f.frames_baked), tuple(forward))
        except (RuntimeError, OSError, ValueError) as e:
            self.report({'ERROR'}, f"Plume: Auto Exposure cannot read the flames' cache "
                                   f"'{f.cache_directory}' ({ui('flames', 'cache_directory')}): "
                                   f"{e}; bake the flames again")
            return {'CANCELLED'}
        stops = flame_meter.exposure_stops(levels)
        if stops is None:
            self.report({'ERROR'}, "Plume: Auto Exposure found no lit flame in the baked frames: "
                                   "is each Flame Source's "
                                   f"{ui('flame_source', 'stops')} far below 0 stops?")
            return {'CANCELLED'}
        scene.cycles.film_exposure = 2.0 ** stops
        text = (f"Plume: Auto Exposure: film exposure {2.0 ** stops:.3g} ({stops:+.1f} stops; "
                f"Render Properties › Film › Exposure), metered on {len(levels)} frames")
        if scene.render.engine != 'CYCLES':
            text += (f". Film Exposure is Cycles' only; in {engine_name(scene)} set Render "
                     f"Properties › Color Management › Exposure to {stops:+.1f}")
            self.report({'WARNING'}, text)
        else:
            self.report({'INFO'}, text)
        return {'FINISHED'}


def engine_name(scene):
    """The render engine as Render Properties › Render Engine shows it ("EEVEE")."""
    engine = scene.render.engine
    item = scene.render.bl_rna.properties["engine"].enum_items.get(engine)
    if item is not None and item.name:
        return item.name
    return engine.replace("BLENDER_", "").replace("_NEXT", "").replace("_", " ").title()


classes = (PLUME_OT_flame_preset, PLUME_OT_flames_auto_exposure)

"""The panel of a built smoke sheet (a Plume streak surface), where an artist who selected one
looks: Properties › Object Data, and the 3D Viewport's sidebar (N) › Plume, which stays in view
in Edit Mode while control points are moved. It says how hand edits work (the Smoke Surfaces
paper's §5) and holds the buttons that act on this sheet: Store / Clear Edits, Bake to
Keyframes, Export Mesh."""

import bpy

from .. import manual
from ..build import surface_edits
from ..operators.manual_open import draw_help
from ..build.surfaces import CACHE_KEY, DOMAIN_KEY

#: What the panel tells the artist, one short line each (panels do not wrap text).
HOW_EDITS_WORK = (
    "Edits follow the smoke on every frame,",
    "turned and carried with the sheet.",
    "Changing frame after Edit Mode stores them;",
    "Store Edits does it at once.",
)


def is_sheet(ob):
    """True for a smoke sheet Build Surfaces made (its control points come from the cache)."""
    return ob is not None and ob.type == 'SURFACE' and CACHE_KEY in ob


def draw_sheet(layout, ob):
    """The sheet's hints and buttons (the operators act on the active sheet and the selected
    ones)."""
    col = layout.column()
    col.label(text=f"Smoke sheet of domain '{ob.get(DOMAIN_KEY, '?')}'", icon='SURFACE_NSURFACE')
    if ob.get(surface_edits.BAKED_KEY):
        col.label(text="Baked to keyframes: edit its keyframes", icon='KEYINGSET')
        return
    box = col.box()
    if ob.mode == 'EDIT':
        box.label(text="Move control points (G, R, S), then Store Edits", icon='INFO')
    else:
        box.label(text="Tab into Edit Mode to move control points", icon='INFO')
    for line in HOW_EDITS_WORK:
        box.label(text=line)
    draw_sheet_buttons(col)


def draw_sheet_buttons(layout):
    """Store / Clear Edits, Bake to Keyframes, Export Mesh (also on the domain's Streak
    Surfaces panel, where they act on all of its sheets)."""
    sub = layout.column(align=True)
    row = sub.row(align=True)
    row.operator("plume.surface_edits_store", icon='EDITMODE_HLT')
    row.operator("plume.surface_edits_clear", icon='X')
    row = sub.row(align=True)
    row.operator("plume.surfaces_bake_keyframes", icon='KEYINGSET')
    row.operator("plume.surfaces_export_mesh", icon='MESH_GRID')


class SheetPanel:
    """Shown when the active object is a smoke sheet."""

    @classmethod
    def poll(cls, context):
        return is_sheet(context.object)

    def draw_header_preset(self, context):
        draw_help(self.layout, manual.STREAKS_EDITS)

    def draw(self, context):
        draw_sheet(self.layout, context.object)


class DATA_PT_plume_sheet(SheetPanel, bpy.types.Panel):
    bl_label = "Plume Smoke Sheet"
    bl_space_type, bl_region_type, bl_context = 'PROPERTIES', 'WINDOW', "data"


class VIEW3D_PT_plume_sheet(SheetPanel, bpy.types.Panel):
    bl_label = "Smoke Sheet"
    bl_space_type, bl_region_type, bl_category = 'VIEW_3D', 'UI', "Plume"


classes = (DATA_PT_plume_sheet, VIEW3D_PT_plume_sheet)

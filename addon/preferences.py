"""Edit › Preferences › Add-ons › Plume: the add-on's entry lists its manuals (each opens in the
web browser, offline), in Blender 3.4 and 4.2+ alike."""

import bpy

from . import manual


class PlumePreferences(bpy.types.AddonPreferences):
    bl_idname = __package__  # "plume", or "bl_ext.<repository>.plume" as an extension

    def draw(self, context):
        layout = self.layout
        col = layout.column(align=True)
        col.label(text="Manual (comes with the add-on, opens in your web browser):")
        flow = col.grid_flow(columns=3, even_columns=True, align=True)
        for page, title in manual.MANUALS:
            flow.operator("plume.manual_open", text=title, icon='HELP').page = page


classes = (PlumePreferences,)

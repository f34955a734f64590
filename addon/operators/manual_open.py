"""plume.manual_open: the Help button (?) of Plume's panels and the manuals listed in Edit ›
Preferences › Add-ons › Plume. Opens a page of the manual that ships with the add-on (see
manual.py) in the system's web browser."""

import bpy
from bpy.props import StringProperty

from .. import manual


def open_in_browser(page_url):
    """Opens a URL as Blender's own help does (wm.url_open); tests replace this function."""
    return bpy.ops.wm.url_open(url=page_url)


class PLUME_OT_manual_open(bpy.types.Operator):
    bl_idname = "plume.manual_open"
    bl_label = "Plume Manual"
    bl_description = ("Open Plume's manual at this part, in your web browser. The manual comes "
                      "with the add-on, so it opens without internet")
    bl_options = {'INTERNAL'}

    page: StringProperty(
        name="Page", default=manual.INDEX,
        description="The manual's page and section to open")

    def execute(self, context):
        if not manual.installed():
            self.report({'ERROR'}, "This copy of Plume has no manual: install Plume again from "
                        "its release zip (Edit › Preferences › Get Extensions › Install from "
                        "Disk; in Blender 3.4, Edit › Preferences › Add-ons › Install)")
            return {'CANCELLED'}
        open_in_browser(manual.url(self.page))
        return {'FINISHED'}


def draw_help(layout, page):
    """A panel header's Help button (?) opening `page` of the manual."""
    layout.operator(PLUME_OT_manual_open.bl_idname, text="", icon='HELP', emboss=False).page = page


classes = (PLUME_OT_manual_open,)

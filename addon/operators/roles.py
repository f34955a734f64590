"""plume.role_set: make the active object (and the other selected meshes) a domain, source,
obstacle or flame source."""

import bpy
from bpy.props import EnumProperty

from ..properties import ROLE_ITEMS


class PLUME_OT_role_set(bpy.types.Operator):
    """Set the Plume role of the active object (and of the other selected meshes, except for
    Domain, which applies to the active object only)"""

    bl_idname = "plume.role_set"
    bl_label = "Set Plume Role"
    bl_options = {'REGISTER', 'UNDO'}

    role: EnumProperty(name="Role", items=ROLE_ITEMS, default='DOMAIN',
                      description="What the objects become in a Plume simulation")

    def execute(self, context):
        active = context.active_object
        if active is None:
            self.report({'ERROR'}, "Plume: no active object to set the role of")
            return {'CANCELLED'}
        targets = [active]
        if self.role != 'DOMAIN':
            targets += [o for o in context.selected_objects
                        if o is not active and o.type == 'MESH']
        if self.role != 'NONE' and active.type != 'MESH':
            role = next(item[1] for item in ROLE_ITEMS if item[0] == self.role)
            self.report({'ERROR'}, f"Plume: '{active.name}' is not a mesh (its type is "
                                   f"{active.type.title()}); "
                                   f"the {role} role needs a mesh object: select one (or add one, "
                                   "Add › Mesh)")
            return {'CANCELLED'}
        for ob in targets:
            previous = ob.plume.role
            ob.plume.role = self.role
            if previous == 'DOMAIN' and self.role != 'DOMAIN':
                # Leaving the domain role: show the object again like before baking.
                ob.display_type = 'TEXTURED'
                ob.hide_render = False
        return {'FINISHED'}


classes = (PLUME_OT_role_set,)

"""Live look settings of a built toon smoke: changing the stretch k, the ramp colours, γ, the
outline colour or the background switch in the panel updates the billboard modifier, the
material and the compositor group at once, with no rebuild (the particles do not depend on
them). Called from the property update callbacks in toon_properties."""

import bpy

from . import toon_compositor, toon_nodes


def apply_look(scene, domain):
    """Pushes the domain's toon look settings into what plume.toon_build made (what exists)."""
    t = domain.plume.domain.toon
    ob = bpy.data.objects.get(t.object_name) if t.object_name else None
    mod = toon_nodes.billboard_modifier(ob) if ob is not None else None
    if mod is not None:
        toon_nodes.set_stretch(mod, t.stretch_factor)
        ob.update_tag()
    mat = bpy.data.materials.get(toon_nodes.material_name(domain))
    if mat is not None:
        toon_nodes.set_ramp(mat, t)
    node = toon_compositor.scene_node(scene) if scene is not None else None
    if node is not None:
        toon_compositor.set_outline(node, t)

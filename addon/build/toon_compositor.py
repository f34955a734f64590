"""Depth-difference outlines in Blender's compositor (cartoon_smoke.txt §2.2, after Deussen &
Strothotte 2000): the node group "Plume Depth Differences" draws a pixel in the outline colour
when any of its four one-sided depth differences divided by the pixel size exceeds γ:

    |z(i+1,j) - z(i,j)| / Δx > γ  or  |z(i,j) - z(i-1,j)| / Δx > γ  or
    |z(i,j+1) - z(i,j)| / Δy > γ  or  |z(i,j) - z(i,j-1)| / Δy > γ,

the same test as _native.depth_differences (neighbours outside the image are skipped; with
Ignore Background, pixels with depth >= Far are never outlined). Each neighbour is the Depth
translated by one pixel. The pixels a translation uncovers read outside the image: Blender 3.4's
Render Layers Depth answers 10e10 there (RenderLayersDepthProg; the background is 1e10), other
compositors answer 0; no rendered depth is either, so 0 < neighbour < OUTSIDE_DEPTH skips them.
Also: scene wiring with the Z pass, and the optional Freestyle style."""

import bpy

from . import datablocks
from .. import blender_compat as compat
from .toon_nodes import link_math

GROUP = "Plume Depth Differences"
NODE = "Plume Depth Differences"
LINESET = "Plume Toon"
#: Depth read outside the image (10e10 in Blender 3.4) is above this; Cycles' background (1e10)
#: and every surface depth are below it.
OUTSIDE_DEPTH = 5.0e10

#: Group inputs: (name, socket type, default).
INPUTS = (("Image", 'NodeSocketColor', (0.0, 0.0, 0.0, 1.0)),
          ("Depth", 'NodeSocketFloat', 0.0),
          ("Gamma", 'NodeSocketFloat', 0.15),
          ("Outline Color", 'NodeSocketColor', (0.0, 0.0, 0.0, 1.0)),
          ("Ignore Background", 'NodeSocketFloat', 0.0),
          ("Far", 'NodeSocketFloat', 1.0e9),
          ("Pixel Width", 'NodeSocketFloat', 1.0),
          ("Pixel Height", 'NodeSocketFloat', 1.0))


def depth_group():
    """The compositor node group (rebuilt in place when it exists). Outputs: Image (outline
    pixels in Outline Color, others from Image) and Outline (1 on outline pixels, else 0)."""
    ng = datablocks.empty_node_group(GROUP, 'CompositorNodeTree')
    new = compat.group_socket_new
    sockets = {name: new(ng, 'INPUT', kind, name) for name, kind, _ in INPUTS}
    for name, _, default in INPUTS:
        sockets[name].default_value = default
    sockets["Gamma"].min_value = 0.0
    sockets["Ignore Background"].min_value, sockets["Ignore Background"].max_value = 0.0, 1.0
    new(ng, 'OUTPUT', 'NodeSocketColor', "Image")
    new(ng, 'OUTPUT', 'NodeSocketFloat', "Outline")
    N, L = ng.nodes.new, ng.links.new
    gin, gout = N('NodeGroupInput'), N('NodeGroupOutput')
    gin.location, gout.location = (-1200, 0), (1100, 0)
    z = gin.outputs["Depth"]

    def math(op, a, b, x, y):
        return link_math(ng, op, a, b, (x, y), kind=compat.COMPOSITOR_MATH)

    conditions = []
    for n, (dx, dy, size) in enumerate(((1, 0, "Pixel Width"), (-1, 0, "Pixel Width"),
                                        (0, 1, "Pixel Height"), (0, -1, "Pixel Height"))):
        y = 600 - n * 300
        t = compat.compositor_translate(ng, dx, dy)
        t.location = (-1000, y)
        L(z, t.inputs["Image"])
        sep = N('CompositorNodeSeparateColor')  # the neighbour's depth exactly (no colour->BW)
        sep.location = (-850, y)
        L(t.outputs["Image"], sep.inputs["Image"])
        # 0 * z + neighbour: the neighbour on z's pixel grid. 4.2-4.5's compositor translates by
        # moving an image's domain and computes a math node on its first input's domain, so z
        # must come first for the shifted depth to be resampled onto z's pixels (uncovered ones
        # read 0); 3.4 and 5.0 shift the pixels themselves, and there this is the identity.
        neighbour = math('ADD', math('MULTIPLY', z, 0.0, -850, y - 120), sep.outputs["Red"],
                         -700, y - 120)
        diff = math('ABSOLUTE', math('SUBTRACT', z, neighbour, -700, y), None, -550, y)
        over = math('GREATER_THAN', math('DIVIDE', diff, gin.outputs[size], -400, y),
                    gin.outputs["Gamma"], -250, y)
        inside = math('MULTIPLY', math('GREATER_THAN', neighbour, 0.0, -550, y - 120),
                      math('LESS_THAN', neighbour, OUTSIDE_DEPTH, -550, y - 240), -400, y - 120)
        conditions.append(math('MULTIPLY', over, inside, -100, y))
    any_ = math('MAXIMUM', math('MAXIMUM', conditions[0], conditions[1], 50, 450),
                math('MAXIMUM', conditions[2], conditions[3], 50, 0), 200, 250)
    # Ignore Background: background = depth not < Far; keep = 1 - ignore * background.
    background = math('SUBTRACT', 1.0, math('LESS_THAN', z, gin.outputs["Far"], 50, -300),
                      200, -300)
    keep = math('SUBTRACT', 1.0, math('MULTIPLY', gin.outputs["Ignore Background"], background,
                                      350, -300), 500, -300)
    outline = math('MULTIPLY', any_, keep, 650, 100)
    mix, fac, a, b, mixed = compat.compositor_mix(ng)
    mix.location = (850, 100)
    L(outline, fac)
    L(gin.outputs["Image"], a)
    L(gin.outputs["Outline Color"], b)
    L(mixed, gout.inputs["Image"])
    L(outline, gout.inputs["Outline"])
    return ng


def set_outline(node, settings):
    """The group node's γ, outline colour and background switch from the toon settings."""
    node.inputs["Gamma"].default_value = float(settings.depth_threshold)
    node.inputs["Outline Color"].default_value = tuple(settings.outline_color)
    node.inputs["Ignore Background"].default_value = 1.0 if settings.ignore_background else 0.0


def scene_node(scene):
    """The scene's "Plume Depth Differences" node, or None."""
    nt = compat.compositor_tree(scene)
    return nt.nodes.get(NODE) if nt is not None else None


def wire_scene(scene, view_layer, settings, far):
    """Render Layers (Z pass on) -> "Plume Depth Differences" -> Composite in the scene's
    compositor, the group node's inputs set from the toon settings. Returns the group node."""
    view_layer.use_pass_z = True
    nt = compat.compositor_tree(scene, create=True)
    compat.compositor_full_precision(scene)  # depths differ by less than half floats resolve
    group = depth_group()
    rl = next((n for n in nt.nodes if n.type == 'R_LAYERS'), None) or nt.nodes.new(
        'CompositorNodeRLayers')
    result = compat.compositor_output(nt)
    comp = result.node
    # A new group node each time: the group's sockets were just rebuilt, and a node kept from an
    # earlier build would hold (and link to) its stale sockets - the second build lost the outline.
    old = nt.nodes.get(NODE)
    if old is not None:
        nt.nodes.remove(old)
    node = nt.nodes.new('CompositorNodeGroup')
    node.name = node.label = NODE
    node.node_tree = group
    node.location = (rl.location.x + 300, rl.location.y)
    comp.location = (node.location.x + 300, node.location.y)
    set_outline(node, settings)
    node.inputs["Far"].default_value = float(far)
    nt.links.new(rl.outputs["Image"], node.inputs["Image"])
    nt.links.new(rl.outputs["Depth"], node.inputs["Depth"])
    nt.links.new(node.outputs["Image"], result)
    return node


def set_freestyle(scene, view_layer, enabled, color, collection=None):
    """Optional style: Freestyle silhouette + border lines from a "Plume Toon" line set (on the
    billboard geometry, not the stencil shapes; §2.2's depth differences stay the default)."""
    if not enabled:
        return  # the artist's own Freestyle setting stays as it is
    scene.render.use_freestyle = True
    fs = view_layer.freestyle_settings
    ls = fs.linesets.get(LINESET) or fs.linesets.new(LINESET)
    ls.select_by_visibility = ls.select_by_edge_types = True
    ls.select_silhouette = ls.select_border = True
    ls.select_crease = False
    if collection is not None:
        ls.select_by_collection = True
        ls.collection = collection
    ls.linestyle.color = tuple(color)[:3]

"""Depth-difference outlines in Blender's compositor ([Cartoon Smoke] §2.2, after Deussen &
Strothotte 2000): the node group "Plume Depth Differences" finds a pixel on the outline when any
of its four one-sided depth differences divided by the pixel size exceeds γ:

    |z(i+1,j) - z(i,j)| / Δx > γ  or  |z(i,j) - z(i-1,j)| / Δx > γ  or
    |z(i,j+1) - z(i,j)| / Δy > γ  or  |z(i,j) - z(i,j-1)| / Δy > γ,

the same test as _native.depth_differences (neighbours outside the image are skipped; with
Ignore Background, pixels with depth >= Far are never outlined): the group's Outline output.

The line drawn has a weight: Outline Width pixels at 1080 lines, scaled by the image height
(a driver keeps "Image Height" at the render's lines), so a 4K render looks like 1080p. The same
test with neighbours k pixels away (k in OFFSETS) marks the pixels at most k pixels from a depth
edge, on both sides. With h half the line width, the pixels first marked at offset k_i (the
ring k_(i-1) < distance <= k_i, n = k_i - k_(i-1) pixels wide) are covered
clamp((h - (k_(i-1) + k_i) / 2) / (n + 1) + 1/2, 0, 1): the line's edge ramps over n + 1 pixels
(two where the rings are one pixel wide: 0.75 / 0.25 at a whole h), so it is soft at any
width, and the line's area stays its width (the first ring: at most h, so a line under a pixel
wide is a lighter one-pixel line). Optional thinning with distance multiplies h by
(D / max(z_near, D))^a, z_near the nearest depth the pixel's neighbours see (so the background
side of a far silhouette thins too).

Each neighbour is the Depth translated by k pixels. The pixels a translation uncovers read
outside the image: Blender 3.4's Render Layers Depth answers 10e10 there (RenderLayersDepthProg;
the background is 1e10), other compositors answer 0; no rendered depth is either, so
0 < neighbour < OUTSIDE_DEPTH skips them. Also: scene wiring with the Z pass, and the optional
Freestyle style."""

from . import datablocks
from .. import blender_compat as compat
from .toon_nodes import link_math

GROUP = "Plume Depth Differences"
NODE = "Plume Depth Differences"
LINESET = "Plume Toon"
#: Depth read outside the image (10e10 in Blender 3.4) is above this; Cycles' background (1e10)
#: and every surface depth are below it.
OUTSIDE_DEPTH = 5.0e10
#: Image height at which Outline Width is in pixels.
REFERENCE_LINES = 1080.0
#: Neighbour distances (px) of the line's rings: a 2 px soft edge up to a 2 px half width (a 4 px
#: line: Outline Width 2 at 4K), wider ramps beyond, up to 8 px (a 16 px line: Outline Width 8
#: at 1080p, 4 at 4K). Each offset costs ~50 compositor nodes, the bulk of the group's time.
OFFSETS = (1, 2, 4, 8)

#: Group inputs: (name, socket type, default).
INPUTS = (("Image", 'NodeSocketColor', (0.0, 0.0, 0.0, 1.0)),
          ("Depth", 'NodeSocketFloat', 0.0),
          ("Gamma", 'NodeSocketFloat', 0.15),
          ("Outline Color", 'NodeSocketColor', (0.0, 0.0, 0.0, 1.0)),
          ("Ignore Background", 'NodeSocketFloat', 0.0),
          ("Far", 'NodeSocketFloat', 1.0e9),
          ("Pixel Width", 'NodeSocketFloat', 1.0),
          ("Pixel Height", 'NodeSocketFloat', 1.0),
          ("Outline Width", 'NodeSocketFloat', 3.0),
          ("Image Height", 'NodeSocketFloat', REFERENCE_LINES),
          ("Thinning", 'NodeSocketFloat', 0.0),
          ("Thinning Distance", 'NodeSocketFloat', 5.0))


def _compare(ng, a, b, epsilon, location):
    """1 where |a - b| <= epsilon, else 0 (the Math node's Compare)."""
    m = ng.nodes.new(compat.COMPOSITOR_MATH)
    m.operation, m.location = 'COMPARE', location
    for i, v in enumerate((a, b, epsilon)):
        ng.links.new(v, m.inputs[i])
    return m.outputs[0]


def _offset_bands(ng, gin, limits, math, k, x):
    """For neighbours k pixels away: (1 where a depth difference exceeds γ times the pixel
    size, the nearest depth among the pixel and its neighbours; outside the image 10e10 in 3.4,
    harmless, or 0 elsewhere, which leaves the lines there at full width)."""
    N, L = ng.nodes.new, ng.links.new
    z = gin.outputs["Depth"]
    conditions, nearest = [], z
    for n, (dx, dy, limit) in enumerate(((k, 0, limits[0]), (-k, 0, limits[0]),
                                         (0, k, limits[1]), (0, -k, limits[1]))):
        y = 900 - n * 450
        t = compat.compositor_translate(ng, dx, dy)
        t.location = (x, y)
        L(z, t.inputs["Image"])
        sep = N('CompositorNodeSeparateColor')  # the neighbour's depth exactly (no colour->BW)
        sep.location = (x + 150, y)
        L(t.outputs["Image"], sep.inputs["Image"])
        # 0 * z + neighbour: the neighbour on z's pixel grid. 4.2-4.5's compositor translates by
        # moving an image's domain and computes a math node on its first input's domain, so z
        # must come first for the shifted depth to be resampled onto z's pixels (uncovered ones
        # read 0); 3.4 and 5.0 shift the pixels themselves, and there this is the identity.
        neighbour = math('ADD', math('MULTIPLY', z, 0.0, x + 150, y - 120), sep.outputs["Red"],
                         x + 300, y - 120)
        near = _compare(ng, z, neighbour, limit, (x + 450, y))  # |z - neighbour| <= γ Δ
        inside = math('MULTIPLY', math('GREATER_THAN', neighbour, 0.0, x + 450, y - 120),
                      math('LESS_THAN', neighbour, OUTSIDE_DEPTH, x + 450, y - 240),
                      x + 600, y - 120)
        conditions.append(math('GREATER_THAN', inside, near, x + 750, y))  # inside, not near
        nearest = math('MINIMUM', nearest, neighbour, x + 750, y - 240)
    any_ = math('MAXIMUM', math('MAXIMUM', conditions[0], conditions[1], x + 900, 700),
                math('MAXIMUM', conditions[2], conditions[3], x + 900, 200), x + 1050, 450)
    return any_, nearest


def depth_group():
    """The compositor node group (rebuilt in place when it exists). Outputs: Image (the line in
    Outline Color over Image), Outline (1 on the pixels §2.2's test outlines, else 0) and Line
    (the line's coverage, 0-1, of its width at this image height)."""
    ng = datablocks.empty_node_group(GROUP, 'CompositorNodeTree')
    new = compat.group_socket_new
    sockets = {name: new(ng, 'INPUT', kind, name) for name, kind, _ in INPUTS}
    for name, _, default in INPUTS:
        sockets[name].default_value = default
    sockets["Gamma"].min_value = 0.0
    sockets["Ignore Background"].min_value, sockets["Ignore Background"].max_value = 0.0, 1.0
    new(ng, 'OUTPUT', 'NodeSocketColor', "Image")
    new(ng, 'OUTPUT', 'NodeSocketFloat', "Outline")
    new(ng, 'OUTPUT', 'NodeSocketFloat', "Line")
    N, L = ng.nodes.new, ng.links.new
    gin, gout = N('NodeGroupInput'), N('NodeGroupOutput')
    z = gin.outputs["Depth"]

    def math(op, a, b, x, y, clamp=False):
        out = link_math(ng, op, a, b, (x, y), kind=compat.COMPOSITOR_MATH)
        out.node.use_clamp = clamp
        return out

    # γ times the pixel size: a depth difference above it is an edge.
    limits = [math('MULTIPLY', gin.outputs["Gamma"], gin.outputs[size], -1000, y)
              for size, y in (("Pixel Width", -1100), ("Pixel Height", -1250))]
    # Half the line width in pixels of this image: width * lines / 1080 / 2.
    half = math('MULTIPLY', gin.outputs["Outline Width"],
                math('DIVIDE', gin.outputs["Image Height"], 2.0 * REFERENCE_LINES, -1000, -1400),
                -850, -1400)
    d = gin.outputs["Thinning Distance"]
    line, outline, previous = None, None, 0
    for i, k in enumerate(OFFSETS):
        x = i * 1500
        marked, nearest = _offset_bands(ng, gin, limits, math, k, x)
        if k == 1:
            outline = marked
        # Thinning: h * (D / max(z_near, D))^a.
        thin = math('POWER', math('DIVIDE', d, math('MAXIMUM', nearest, d, x + 900, -1400),
                                  x + 1050, -1400), gin.outputs["Thinning"], x + 1200, -1400)
        h = math('MULTIPLY', half, thin, x + 1350, -1400)
        ramp = k - previous + 1.0
        cover = math('ADD', math('DIVIDE', math('SUBTRACT', h, (previous + k) / 2.0, x + 900,
                                                -1200), ramp, x + 1050, -1200), 0.5,
                     x + 1200, -1200, clamp=True)
        if k == 1:
            cover = math('MINIMUM', cover, h, x + 1350, -1100)
        band = math('MULTIPLY', marked, cover, x + 1350, -1200)
        line = band if line is None else math('MAXIMUM', line, band, x + 1500, -1200)
        previous = k
    x = len(OFFSETS) * 1500
    gin.location, gout.location = (-1300, 0), (x + 900, 0)
    # Ignore Background: background = depth not < Far; keep = 1 - ignore * background.
    background = math('SUBTRACT', 1.0, math('LESS_THAN', z, gin.outputs["Far"], x, -300),
                      x + 150, -300)
    keep = math('SUBTRACT', 1.0, math('MULTIPLY', gin.outputs["Ignore Background"], background,
                                      x + 300, -300), x + 450, -300)
    outline = math('MULTIPLY', outline, keep, x + 600, 100)
    line = math('MULTIPLY', line, keep, x + 600, -100)
    mix, fac, a, b, mixed = compat.compositor_mix(ng)
    mix.location = (x + 750, 0)
    L(line, fac)
    L(gin.outputs["Image"], a)
    L(gin.outputs["Outline Color"], b)
    L(mixed, gout.inputs["Image"])
    L(outline, gout.inputs["Outline"])
    L(line, gout.inputs["Line"])
    return ng


def set_outline(node, settings):
    """The group node's γ, outline colour, background switch, line width and thinning from the
    toon settings."""
    node.inputs["Gamma"].default_value = float(settings.depth_threshold)
    node.inputs["Outline Color"].default_value = tuple(settings.outline_color)
    node.inputs["Ignore Background"].default_value = 1.0 if settings.ignore_background else 0.0
    node.inputs["Outline Width"].default_value = float(settings.outline_width)
    node.inputs["Thinning"].default_value = float(settings.outline_thinning)
    node.inputs["Thinning Distance"].default_value = float(settings.outline_thinning_distance)


def drive_image_height(node, scene):
    """Keeps the group node's Image Height at the render's lines (resolution Y times the
    percentage), also when they change after the build, with a driver (a simple expression:
    evaluated without Python, so it works with scripts not trusted)."""
    socket = node.inputs["Image Height"]
    r = scene.render
    socket.default_value = r.resolution_y * r.resolution_percentage / 100.0
    tree = node.id_data
    path = socket.path_from_id("default_value")
    tree.driver_remove(path)
    driver = tree.driver_add(path).driver
    driver.type = 'SCRIPTED'
    for name, prop in (("h", "render.resolution_y"), ("p", "render.resolution_percentage")):
        var = driver.variables.new()
        var.name, var.type = name, 'SINGLE_PROP'
        var.targets[0].id_type = 'SCENE'
        var.targets[0].id = scene
        var.targets[0].data_path = prop
    driver.expression = "h * p / 100"


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
    drive_image_height(node, scene)
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

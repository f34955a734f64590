"""Toon smoke rendering in Blender ([Cartoon Smoke] §2.2-2.3): the geometry-nodes group
"Plume Toon Billboards" (one camera-facing quad per point, `size` wide, rotated in the image
plane along the point's projected velocity and stretched in proportion to its speed, Figure 4)
and the flat toon material whose stencil alpha is a hard cut-out (alpha CLIP), so that the Depth pass is written
only where the stencil is opaque (with the view layer's pass_alpha_threshold)."""

import bpy

from . import datablocks
from .. import blender_compat as compat

GROUP = "Plume Toon Billboards"
#: Alpha above which a stencil pixel is opaque (material cut-out and Cycles pass threshold).
ALPHA_THRESHOLD = 0.5
#: Point attribute of the billboards holding the stencil coordinates (u, v, 0).
UV_ATTRIBUTE = "plume_uv"
#: Point attribute with the particle velocity (m/s), which orients and stretches its stencil.
VELOCITY_ATTRIBUTE = "plume_velocity"
#: Point attribute with the colour-ramp coordinate in [0, 1] (written by toon_points). Not
#: "color": Cycles maps that name to its standard volume colour, and a mesh attribute of that
#: name reads as 0 in the shader.
COLOR_ATTRIBUTE = "plume_color"


def link_math(nt, op, a, b=None, location=(0, 0), kind="ShaderNodeMath"):
    """A math node of `kind` (shader, vector or compositor math) computing `op`(a, b), whose
    inputs are sockets or numbers; returns its output."""
    m = nt.nodes.new(kind)
    m.operation, m.location = op, location
    for k, v in ((0, a), (1, b)):
        if isinstance(v, (int, float)):
            m.inputs[k].default_value = v
        elif v is not None:
            nt.links.new(v, m.inputs[k])
    return m.outputs[0]


def billboard_group():
    """The "Plume Toon Billboards" geometry-nodes group (rebuilt in place when it exists).
    Inputs: Geometry (points with size and velocity attributes), Camera (object), Material,
    Stretch Factor (k), Perspective. The orientation is computed here, from the camera as the
    depsgraph evaluates it for the frame drawn, so an animated camera never lags a frame."""
    ng = datablocks.empty_node_group(GROUP, 'GeometryNodeTree')
    new = compat.group_socket_new
    new(ng, 'INPUT', 'NodeSocketGeometry', "Geometry")
    new(ng, 'INPUT', 'NodeSocketObject', "Camera")
    new(ng, 'INPUT', 'NodeSocketMaterial', "Material")
    k = new(ng, 'INPUT', 'NodeSocketFloat', "Stretch Factor")
    k.min_value, k.default_value = 0.0, 0.5
    k.description = "k: the stencil stretches to 1 + k |v_screen| along the motion (Figure 4)"
    persp = new(ng, 'INPUT', 'NodeSocketBool', "Perspective")
    persp.default_value = True
    new(ng, 'OUTPUT', 'NodeSocketGeometry', "Geometry")
    N, L = ng.nodes.new, ng.links.new
    gin, gout = N('NodeGroupInput'), N('NodeGroupOutput')
    gin.location, gout.location = (-1800, 0), (900, 0)

    def attribute(name, kind, y):
        a = N('GeometryNodeInputNamedAttribute')
        a.data_type, a.location = kind, (-1600, y)
        a.inputs["Name"].default_value = name
        return next(o for o in a.outputs if o.enabled)  # one output per type, the type's shown

    size = attribute("size", 'FLOAT', -300)
    velocity = attribute(VELOCITY_ATTRIBUTE, 'FLOAT_VECTOR', -450)

    # The camera's world frame: the quad's local z is the view axis, so it faces the camera.
    cam = N('GeometryNodeObjectInfo')
    cam.transform_space, cam.location = 'ORIGINAL', (-1600, 300)
    L(gin.outputs["Camera"], cam.inputs["Object"])

    def camera_axis(vec, y):
        r = N('ShaderNodeVectorRotate')
        r.rotation_type, r.location = 'EULER_XYZ', (-1400, y)
        r.inputs["Vector"].default_value = vec
        L(cam.outputs["Rotation"], r.inputs["Rotation"])
        return r.outputs["Vector"]

    right, up = camera_axis((1.0, 0.0, 0.0), 300), camera_axis((0.0, 1.0, 0.0), 150)
    back = camera_axis((0.0, 0.0, 1.0), 0)

    def vmath(op, a, b, y, x=-1200):
        return link_math(ng, op, a, b, (x, y), "ShaderNodeVectorMath")

    def dot(a, b, y):
        d = N('ShaderNodeVectorMath')
        d.operation, d.location = 'DOT_PRODUCT', (-1000, y)
        L(a, d.inputs[0])
        L(b, d.inputs[1])
        return d.outputs["Value"]

    # Figure 4, as _native.toon_billboards: position p and velocity v in the camera frame; the
    # image-plane velocity s = v_xy, minus p_xy v_z / p_z in front of a perspective camera
    # (d/dt of the projection, times the depth).
    pos = N('GeometryNodeInputPosition')
    pos.location = (-1600, -150)
    rel = vmath('SUBTRACT', pos.outputs["Position"], cam.outputs["Location"], -150)
    px, py, pz = dot(rel, right, -100), dot(rel, up, -200), dot(rel, back, -300)
    vx, vy, vz = dot(velocity, right, -400), dot(velocity, up, -500), dot(velocity, back, -600)
    in_front = link_math(ng, 'MULTIPLY', link_math(ng, 'LESS_THAN', pz, 0.0, (-800, -300)),
                         gin.outputs["Perspective"], (-650, -300))
    f = link_math(ng, 'MULTIPLY', link_math(ng, 'DIVIDE', vz, pz, (-800, -500)), in_front,
                  (-650, -500))  # DIVIDE gives 0 for p_z = 0
    sx = link_math(ng, 'SUBTRACT', vx, link_math(ng, 'MULTIPLY', px, f, (-500, -350)), (-350, -350))
    sy = link_math(ng, 'SUBTRACT', vy, link_math(ng, 'MULTIPLY', py, f, (-500, -450)), (-350, -450))
    angle = link_math(ng, 'ARCTAN2', sy, sx, (-200, -400))
    s_xy = N('ShaderNodeCombineXYZ')
    s_xy.location = (-200, -550)
    L(sx, s_xy.inputs["X"])
    L(sy, s_xy.inputs["Y"])
    speed = N('ShaderNodeVectorMath')
    speed.operation, speed.location = 'LENGTH', (-50, -550)
    L(s_xy.outputs["Vector"], speed.inputs[0])
    stretch = link_math(ng, 'MULTIPLY_ADD', speed.outputs["Value"], gin.outputs["Stretch Factor"],
                        (100, -550))
    stretch.node.inputs[2].default_value = 1.0  # 1 + k |s|

    # Stretch axis in the image plane: cos(angle) right + sin(angle) up (Figure 4).
    cos_a = link_math(ng, 'COSINE', angle, location=(-50, -250))
    sin_a = link_math(ng, 'SINE', angle, location=(-50, -400))

    def scaled(vec, factor, y):
        v = N('ShaderNodeVectorMath')
        v.operation, v.location = 'SCALE', (100, y)
        L(vec, v.inputs[0])
        L(factor, v.inputs["Scale"])
        return v.outputs["Vector"]

    axis = vmath('ADD', scaled(right, cos_a, 150), scaled(up, sin_a, 0), 100, x=250)
    # Rotate about the view axis (pivot z) until local x lies along the stretch axis.
    align = N('FunctionNodeAlignEulerToVector')
    align.axis, align.pivot_axis, align.location = 'X', 'Z', (400, 200)
    L(cam.outputs["Rotation"], align.inputs["Rotation"])
    L(axis, align.inputs["Vector"])
    # Scale (size stretch, size, 1): the quad is 1 m wide, so `size` is the stencil diameter.
    xyz = N('ShaderNodeCombineXYZ')
    xyz.location = (400, -300)
    L(link_math(ng, 'MULTIPLY', size, stretch, (250, -350)), xyz.inputs["X"])
    L(size, xyz.inputs["Y"])
    xyz.inputs["Z"].default_value = 1.0

    quad = N('GeometryNodeMeshGrid')  # 1x1 m, 2x2 vertices, with its "uv_map" in [0, 1]²
    quad.location = (-400, -550)
    quad.inputs["Size X"].default_value = quad.inputs["Size Y"].default_value = 1.0
    quad.inputs["Vertices X"].default_value = quad.inputs["Vertices Y"].default_value = 2
    # Stencil coordinates in [0, 1]² as a 3-D point attribute (Cycles 3.4 does not read the
    # grid's 2-D "uv_map" through an Attribute node): position + 0.5 on the 1 m quad.
    pos = N('GeometryNodeInputPosition')
    pos.location = (-400, -750)
    uv = N('GeometryNodeStoreNamedAttribute')
    uv.data_type, uv.domain, uv.location = 'FLOAT_VECTOR', 'POINT', (-200, -550)
    uv.inputs["Name"].default_value = UV_ATTRIBUTE
    L(quad.outputs["Mesh"], uv.inputs["Geometry"])
    L(link_math(ng, 'ADD', pos.outputs["Position"], None, (-300, -750), "ShaderNodeVectorMath"),
      uv.inputs["Value"])
    uv.inputs["Value"].links[0].from_node.inputs[1].default_value = (0.5, 0.5, 0.0)
    setmat = N('GeometryNodeSetMaterial')
    setmat.location = (0, -550)
    L(uv.outputs["Geometry"], setmat.inputs["Geometry"])
    L(gin.outputs["Material"], setmat.inputs["Material"])

    inst = N('GeometryNodeInstanceOnPoints')
    inst.location = (300, 0)
    L(gin.outputs["Geometry"], inst.inputs["Points"])
    L(setmat.outputs["Geometry"], inst.inputs["Instance"])
    L(align.outputs["Rotation"], inst.inputs["Rotation"])
    L(xyz.outputs["Vector"], inst.inputs["Scale"])
    # Realized, so the shader reads the points' attributes (colour) as plain mesh attributes.
    real = N('GeometryNodeRealizeInstances')
    real.location = (600, 0)
    L(inst.outputs["Instances"], real.inputs["Geometry"])
    L(real.outputs["Geometry"], gout.inputs["Geometry"])
    return ng


def is_perspective(camera):
    return camera.type != 'CAMERA' or camera.data.type != 'ORTHO'


def set_camera(mod, camera):
    """Points the billboards at `camera` (perspective or not). False when nothing changed."""
    ids = compat.group_input_ids(mod.node_group)
    persp = is_perspective(camera)
    if (compat.modifier_input(mod, ids["Camera"]) == camera
            and bool(compat.modifier_input(mod, ids["Perspective"])) == persp):
        return False
    compat.set_modifier_input(mod, ids["Camera"], camera)
    compat.set_modifier_input(mod, ids["Perspective"], persp)
    return True


def billboard_modifier(ob):
    """The object's "Plume Toon Billboards" modifier, or None."""
    mod = ob.modifiers.get(GROUP)
    return mod if mod is not None and mod.type == 'NODES' and mod.node_group else None


def apply_billboards(ob, camera, material, stretch_factor):
    """Adds (or updates) the object's "Plume Toon Billboards" modifier."""
    ng = billboard_group()
    mod = ob.modifiers.get(GROUP)
    if mod is None or mod.type != 'NODES':
        mod = ob.modifiers.new(GROUP, 'NODES')
    mod.node_group = ng
    ids = compat.group_input_ids(ng)
    set_camera(mod, camera)
    compat.set_modifier_input(mod, ids["Material"], material)
    set_stretch(mod, stretch_factor)
    ob.data.update()
    return mod


def material_name(domain):
    return f"Plume Toon {domain.name}"


def set_ramp(mat, settings):
    """The material's colour ramp ends from the toon settings (False without a ramp node)."""
    ramp = next((n for n in mat.node_tree.nodes if n.type == 'VALTORGB'), None) if mat.node_tree \
        else None
    if ramp is None:
        return False
    els = ramp.color_ramp.elements
    els[0].color, els[-1].color = tuple(settings.ramp_color_low), tuple(settings.ramp_color_high)
    return True


def set_stretch(mod, stretch_factor):
    ids = compat.group_input_ids(mod.node_group)
    compat.set_modifier_input(mod, ids["Stretch Factor"], float(stretch_factor))


def toon_material(name, stencil_path, settings):
    """Flat toon shading (§2.2): Emission coloured by the ramp of the point's COLOR_ATTRIBUTE, cut
    out by the stencil's alpha > ALPHA_THRESHOLD (mixed with Transparent, so 0 or 1, never blended)."""
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    mat.use_nodes = True
    compat.set_transparency(mat, 'CLIP', ALPHA_THRESHOLD)
    mat.use_backface_culling = False
    nt = mat.node_tree
    nt.nodes.clear()
    N, L = nt.nodes.new, nt.links.new
    uv = N('ShaderNodeAttribute')
    uv.attribute_type, uv.attribute_name, uv.location = 'GEOMETRY', UV_ATTRIBUTE, (-900, 200)
    tex = N('ShaderNodeTexImage')
    tex.location, tex.extension, tex.interpolation = (-700, 200), 'CLIP', 'Linear'
    img = bpy.data.images.load(stencil_path, check_existing=True)
    img.reload()  # a regenerated stencil file replaces what Blender had loaded
    tex.image = img
    L(uv.outputs["Vector"], tex.inputs["Vector"])
    opaque = link_math(nt, 'GREATER_THAN', tex.outputs["Alpha"], ALPHA_THRESHOLD, (-450, 200))

    col = N('ShaderNodeAttribute')
    col.attribute_type, col.location = 'GEOMETRY', (-900, -150)
    col.attribute_name = COLOR_ATTRIBUTE
    ramp = N('ShaderNodeValToRGB')
    ramp.location = (-650, -150)
    L(col.outputs["Fac"], ramp.inputs["Fac"])
    em = N('ShaderNodeEmission')
    em.location = (-300, -150)
    em.inputs["Strength"].default_value = 1.0
    L(ramp.outputs["Color"], em.inputs["Color"])
    tr = N('ShaderNodeBsdfTransparent')
    tr.location = (-300, 50)
    mix = N('ShaderNodeMixShader')
    mix.location = (-50, 50)
    L(opaque, mix.inputs["Fac"])
    L(tr.outputs[0], mix.inputs[1])
    L(em.outputs[0], mix.inputs[2])
    out = N('ShaderNodeOutputMaterial')
    out.location = (150, 50)
    L(mix.outputs[0], out.inputs["Surface"])
    set_ramp(mat, settings)
    return mat

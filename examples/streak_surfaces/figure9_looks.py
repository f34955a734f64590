"""How compare_representations.py renders the alternatives of Figure 9 of [Smoke Surfaces]
fairly: a Principled Volume lit by the scene, particles as a particle artist draws them (small
soft semi-transparent glowing specks, fading with the density they carry), each rendered for at
least the time the sheets take (render_matched), and what a compositor sees in a panel
(measure: the smoke's light, by which the looks are matched, its speckle and its edges). Run
inside Blender; needs the Plume add-on.
"""

import math
import os
import time

import bpy

import scene_kit

#: Colour of the smoke in every panel: the incense sheets' Sheet Color (incense.py).
SMOKE_COLOR = (0.9, 0.92, 1.0)
#: A pixel shows smoke when some channel is this much above the background's (the median pixel).
SMOKE_LEVEL = 0.03
#: Samples of the render that measures how long a sample takes (render_matched).
PROBE_SAMPLES = 4
#: render_matched aims this much above the time it is given, so that it is not undershot.
MATCH_MARGIN = 1.1
#: The particles' density attribute. Not "density": Cycles takes that name for a volume's
#: density grid and reads 0 for it on a point cloud.
DENSITY_ATTRIBUTE = "smoke_density"
#: Label of the speck material's node holding the opacity (set_speck_opacity()).
SPECK_OPACITY_LABEL = "Speck Opacity"


def set_volume_look(volume_ob, density):
    """The Principled Volume of `volume_ob`: density scale `density`, the smoke's colour, lit
    by the scene's sun (single scattering when the scene has no volume bounces)."""
    for slot in volume_ob.material_slots:
        for node in slot.material.node_tree.nodes:
            if node.type == 'PRINCIPLED_VOLUME':
                node.inputs["Density"].default_value = density
                node.inputs["Color"].default_value = (*SMOKE_COLOR, 1.0)


def particles_object(dom, frame, radius, opacity, full_density, strength):
    """The streaklines' particles inside the domain at `frame` as a point cloud (geometry nodes
    Mesh to Points of `radius` m): each a soft glowing speck, emission `strength` in the smoke's
    colour, of opacity `opacity` where the particle carries `full_density` or more and less where
    it carries less (the smoke has thinned there), fading to nothing at its rim, as a particle
    artist would draw smoke. Figure 9 (c), (d)."""
    from plume import _native, cache
    folder = os.path.join(bpy.path.abspath(dom.plume.domain.cache_directory), dom.name)
    snap = _native.read_streak_file(cache.streak_path(folder, frame))
    keep = snap["outside"] == 0
    mesh = bpy.data.meshes.new(f"{dom.name}_particles")
    mesh.from_pydata([tuple(p) for p in snap["positions"][keep]], [], [])
    attr = mesh.attributes.new(DENSITY_ATTRIBUTE, 'FLOAT', 'POINT')
    attr.data.foreach_set("value", snap["density"][keep].astype("float32"))
    ob = bpy.data.objects.new(mesh.name, mesh)
    bpy.context.scene.collection.objects.link(ob)
    ng = bpy.data.node_groups.new("ParticlePoints", 'GeometryNodeTree')
    new_socket = scene_kit.compat().group_socket_new
    new_socket(ng, 'INPUT', 'NodeSocketGeometry', "Geometry")
    new_socket(ng, 'OUTPUT', 'NodeSocketGeometry', "Geometry")
    n_in, n_out = ng.nodes.new("NodeGroupInput"), ng.nodes.new("NodeGroupOutput")
    to_points = ng.nodes.new("GeometryNodeMeshToPoints")
    to_points.inputs["Radius"].default_value = radius
    set_mat = ng.nodes.new("GeometryNodeSetMaterial")
    set_mat.inputs["Material"].default_value = speck_material(opacity, full_density, strength)
    ng.links.new(n_in.outputs[0], to_points.inputs["Mesh"])
    ng.links.new(to_points.outputs[0], set_mat.inputs["Geometry"])
    ng.links.new(set_mat.outputs[0], n_out.inputs[0])
    ob.modifiers.new("Points", 'NODES').node_group = ng
    return ob


def speck_material(opacity, full_density, strength):
    """Emission mixed with transparency by opacity × min(density / full_density, 1) ×
    (1 - facing): a speck is densest at its centre and fades to its rim (the point renders as a
    small sphere)."""
    mat = bpy.data.materials.new("ParticleSpeck")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    N, link = nt.nodes.new, nt.links.new
    density = N("ShaderNodeAttribute")
    density.attribute_name = DENSITY_ATTRIBUTE
    facing = N("ShaderNodeLayerWeight")
    centre = N("ShaderNodeMath")  # 1 - facing: 1 at the speck's centre, 0 at its rim
    centre.operation = 'SUBTRACT'
    centre.inputs[0].default_value = 1.0
    link(facing.outputs["Facing"], centre.inputs[1])
    dense = N("ShaderNodeMath")
    dense.operation = 'DIVIDE'
    dense.use_clamp = True
    link(density.outputs["Fac"], dense.inputs[0])
    dense.inputs[1].default_value = full_density
    peak = N("ShaderNodeMath")
    peak.operation = 'MULTIPLY'
    peak.label = SPECK_OPACITY_LABEL
    link(dense.outputs[0], peak.inputs[0])
    peak.inputs[1].default_value = opacity
    alpha = N("ShaderNodeMath")
    alpha.operation = 'MULTIPLY'
    link(peak.outputs[0], alpha.inputs[0])
    link(centre.outputs[0], alpha.inputs[1])
    em = N("ShaderNodeEmission")
    em.inputs["Color"].default_value = (*SMOKE_COLOR, 1.0)
    em.inputs["Strength"].default_value = strength
    mix = N("ShaderNodeMixShader")
    link(alpha.outputs[0], mix.inputs["Fac"])
    link(N("ShaderNodeBsdfTransparent").outputs[0], mix.inputs[1])
    link(em.outputs[0], mix.inputs[2])
    link(mix.outputs[0], N("ShaderNodeOutputMaterial").inputs["Surface"])
    return mat


def set_speck_opacity(specks, opacity):
    """Sets the opacity of the specks of particles_object() `specks`."""
    ng = specks.modifiers["Points"].node_group
    mat = next(n for n in ng.nodes if n.type == 'SET_MATERIAL').inputs["Material"].default_value
    next(n for n in mat.node_tree.nodes if n.label == SPECK_OPACITY_LABEL).inputs[1].default_value = opacity


def show_only(scene, visible):
    """Hides every object but `visible` (and the camera and lights) from renders."""
    for ob in scene.objects:
        if ob.type not in {'CAMERA', 'LIGHT'}:
            ob.hide_render = ob not in visible


def render(scene, path, samples):
    """Renders the current frame to `path` with `samples` samples. Returns (wall seconds, Cycles'
    own seconds of sampling)."""
    scene.cycles.samples = samples
    scene.render.filepath = path
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - t0, sampling_seconds(path)


def render_matched(scene, path, seconds, probe=PROBE_SAMPLES):
    """Renders the current frame to `path` with as many samples as take about MATCH_MARGIN ×
    `seconds` (wall), and never fewer than `probe`: a render at `probe` samples measures the time
    a sample takes and the time around the sampling (loading, building), then the final render
    runs; when it came out faster than `seconds` (the machine's load changed), it runs once more
    with the samples scaled up. Returns (wall seconds, samples)."""
    wall, sampling = render(scene, path, probe)
    per_sample, around = max(sampling, 1e-3) / probe, max(wall - sampling, 0.0)
    samples = max(probe, math.ceil((MATCH_MARGIN * seconds - around) / per_sample))
    if samples == probe:
        return wall, samples
    wall, sampling = render(scene, path, samples)
    if wall < seconds:
        samples = math.ceil(samples * (MATCH_MARGIN * seconds - wall + sampling)
                            / max(sampling, 1e-3))
        wall, _ = render(scene, path, samples)
    return wall, samples


def match_light(scene, path, apply, value, target, samples, rounds=6, tolerance=0.08):
    """Scales a panel's look setting (`apply(value)`: a volume's density scale, the specks'
    opacity) until its light (measure()) is about `target`, the sheets': a probe render at
    `samples` per round (near the final count: a grainy render measures more light than a clean
    one, 0.20 against 0.11 mean brightness at 8 and 512 samples), the value scaled by
    target / light (light grows about in proportion for faint smoke), until a probe is within
    `tolerance` of the target (a probe that misjudged the light is caught by the next one).
    Leaves the last value applied and returns it."""
    for _ in range(rounds):
        apply(value)
        render(scene, path, samples)
        m = measure(path)
        light = m["light"]
        if light <= 0.0:  # never silently keep the starting value: say what the probe saw
            raise RuntimeError(f"figure9_looks.match_light: the probe render {path} at "
                               f"{samples} samples shows no smoke ({m}), value {value:g}")
        if abs(light / target - 1.0) <= tolerance:
            return value
        value *= min(max(target / light, 0.25), 4.0)
    apply(value)
    return value


def sampling_seconds(path):
    """Cycles' render time without synchronisation, from the metadata of the PNG it wrote
    ("cycles.<view layer>.render_time", mm:ss.cc); 0 when absent."""
    import re
    with open(path, "rb") as f:
        data = f.read()
    m = re.search(rb"cycles\.[^\x00]*\.render_time\x00(?:(\d+):)?(\d+):(\d+(?:\.\d+)?)", data)
    if not m:
        return 0.0
    hours = float(m.group(1) or 0)
    return hours * 3600.0 + float(m.group(2)) * 60.0 + float(m.group(3))


def measure(path):
    """What a compositor sees in PNG `path`, from each pixel's brightness above the background
    (the mean of its channels minus the median pixel's; the smoke's pixels are those with some
    channel SMOKE_LEVEL above the background's):
    - "share": the smoke's share of the picture; "mean": its mean brightness;
    - "light": their product × 1000, the smoke's light summed over the picture per 1000 pixels
      (what the panels are matched by);
    - "speckle": the share of that light in detail finer than 3 pixels (|b - its 3 x 3 mean|
      summed, over b summed): high for isolated specks or grain, low for smooth sheets or a
      clean volume;
    - "edge": the 99th percentile of the brightness gradient (per pixel) over the smoke: high
      where the smoke has sharp, high-contrast outlines, low for a soft volume."""
    import numpy as np
    px = scene_kit.png_pixels(path)
    above = px - np.median(px.reshape(-1, 3), axis=0)
    smoke = above.max(axis=2) > SMOKE_LEVEL
    b = np.clip(above.mean(axis=2), 0.0, None)
    if not smoke.any():
        return {"share": 0.0, "mean": 0.0, "light": 0.0, "speckle": 0.0, "edge": 0.0}
    h, w = b.shape
    pad = np.pad(b, 1, mode='edge')
    box = sum(pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
              for dy in (-1, 0, 1) for dx in (-1, 0, 1)) / 9.0
    gy, gx = np.gradient(b)
    share, mean = float(smoke.mean()), float(above[smoke].mean())
    return {"share": share, "mean": mean, "light": 1000.0 * share * mean,
            "speckle": float(np.abs(b - box).sum() / max(b.sum(), 1e-9)),
            "edge": float(np.percentile(np.hypot(gx, gy)[smoke], 99))}

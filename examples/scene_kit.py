"""Shared pieces of the example scripts (run inside Blender): arguments, an empty scene with the
add-on enabled, a dark studio (camera, sun, world), Cycles CPU settings, and a strip image of
several rendered frames for the manuals.

The examples sit in one folder per pipeline (examples/<pipeline>/NAME.py, beside that
pipeline's manual, README.md); this module and the other kits stay in examples/ so that every
example imports them the same way, as its first lines after the standard imports::

    HERE = os.path.dirname(os.path.abspath(__file__))
    sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/
    import scene_kit
"""

import math
import os
import sys
import time

import addon_utils
import bpy


def parse_args(usage, default_frames):
    """(out_dir, frames) from the arguments after ``--``; exits with `usage` when they are bad."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(usage)
    out_dir = os.path.abspath(argv[0])
    try:
        frames = int(argv[1]) if len(argv) > 1 else default_frames
    except ValueError:
        sys.exit(f"FRAMES must be an integer (got {argv[1]!r})\n{usage}")
    if frames < 1:
        sys.exit(f"FRAMES must be at least 1 (got {frames})\n{usage}")
    os.makedirs(out_dir, exist_ok=True)
    return out_dir, frames


def new_scene():
    """Enables the add-on and removes every object of the factory scene."""
    if addon_utils.enable("plume", default_set=True) is None:
        sys.exit("the plume add-on is not installed (see README)")
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    return bpy.context.scene


def save_blend(out_dir, name):
    """Saves OUT_DIR/NAME.blend (no .blend1), so '//' cache paths land in OUT_DIR."""
    bpy.context.preferences.filepaths.save_version = 0
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out_dir, name + ".blend"))


def camera(scene, location, rotation_deg=None, lens=50.0, name="Camera", target=None):
    """The scene camera at `location`, turned by `rotation_deg` (XYZ Euler) or looking at the
    point `target` (image up towards +z)."""
    from mathutils import Vector
    cam = bpy.data.objects.new(name, bpy.data.cameras.new(name))
    scene.collection.objects.link(cam)
    cam.location = location
    if target is not None:
        view = Vector(target) - Vector(location)
        cam.rotation_euler = view.to_track_quat('-Z', 'Y').to_euler()
    else:
        cam.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
    cam.data.lens = lens
    scene.camera = cam
    return cam


def dark_studio(scene, world_color=(0.012, 0.014, 0.02), sun_energy=4.0):
    """A sun from the upper left and a near-black world."""
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", 'SUN'))
    sun.data.energy = sun_energy
    sun.data.angle = math.radians(3.0)
    sun.rotation_euler = (math.radians(50.0), 0.0, math.radians(-40.0))
    scene.collection.objects.link(sun)
    plain_world(scene, world_color)
    return sun


def plain_world(scene, color):
    """The scene's world: one plain colour, strength 1."""
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = 1.0


def cycles(scene, width, height, samples, filepath):
    """Cycles on the CPU, no denoiser (Debian's Blender has no OIDN), PNG output. Streak sheets
    overlap in many layers, so transparent bounces are raised well above the default 8 (with 8
    the light of the deepest layers is cut off and shows as black patches)."""
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.transparent_max_bounces = 64
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    scene.render.filepath = filepath


def render_frames(scene, frames, pattern):
    """Renders each frame of `frames` to pattern % frame; returns the paths."""
    paths = []
    for f in frames:
        scene.frame_set(f)
        scene.render.filepath = pattern % f
        bpy.ops.render.render(write_still=True)
        paths.append(scene.render.filepath)
    return paths


def strip(paths, out_path, gap=4, columns=None):
    """Puts equally sized PNGs side by side (dark gap between them) into one PNG; with
    `columns`, in rows of that many images (the first row on top)."""
    import numpy as np
    images = [png_pixels(p, alpha=True) for p in paths]  # Blender's rows run bottom to top
    columns = columns or len(images)
    rows = (len(images) + columns - 1) // columns
    ch, cw = max(i.shape[0] for i in images), max(i.shape[1] for i in images)
    h, w = rows * ch + gap * (rows - 1), columns * cw + gap * (columns - 1)
    out = np.zeros((h, w, 4), dtype=np.float32)
    out[..., 3] = 1.0
    for n, i in enumerate(images):
        y, x = h - (n // columns + 1) * ch - (n // columns) * gap, (n % columns) * (cw + gap)
        out[y:y + i.shape[0], x:x + i.shape[1]] = i
    img = bpy.data.images.new("plume_strip", w, h, alpha=True)
    img.pixels.foreach_set(out.ravel())
    img.filepath_raw = out_path
    img.file_format = 'PNG'
    img.save()
    bpy.data.images.remove(img)
    return out_path


def domain_cube(name, size, location, resolution, frames):
    """A cube mesh made a Plume domain: `resolution` cells on its longest axis, frames 1..frames,
    cache in '//plume_cache/' (next to the saved .blend)."""
    bpy.ops.mesh.primitive_cube_add(size=size, location=location)
    dom = bpy.context.active_object
    dom.name = name
    bpy.ops.plume.role_set(role='DOMAIN')
    d = dom.plume.domain
    d.resolution = resolution
    d.frame_start, d.frame_end = 1, frames
    d.cache_directory = "//plume_cache/"
    return dom


def bake_surfaces(dom, tag):
    """Bake, the Most Surfaces threshold (the peak of the Figure-4 curve the panel shows), Build
    Surfaces; the Volume object is hidden from renders so the sheets show alone, and the .blend
    is saved. Returns (bake seconds, build seconds, h0, surface objects); exits on failure."""
    bpy.context.view_layer.objects.active = dom
    bake_s = run_op(bpy.ops.plume.bake, tag, "the bake")
    if bpy.ops.plume.surfaces_pick_threshold() != {'FINISHED'}:
        sys.exit(f"{tag}: no threshold joins two streaklines")
    build_s = run_op(bpy.ops.plume.surfaces_build, tag, "Build Surfaces")
    smoke = bpy.data.objects.get(dom.plume.domain.volume_object)
    if smoke is not None:
        smoke.hide_render = True
    bpy.ops.wm.save_mainfile()
    surfaces = [o for o in bpy.data.objects if o.type == 'SURFACE']
    return bake_s, build_s, dom.plume.domain.streak_threshold, surfaces


def render_frames_timed(scene, frames, out_dir, prefix):
    """Renders `frames` to OUT_DIR/PREFIX_####.png; returns (seconds per frame, paths)."""
    t0 = time.perf_counter()
    paths = render_frames(scene, frames, os.path.join(out_dir, prefix + "_%04d.png"))
    return (time.perf_counter() - t0) / len(paths), paths


def render_strip(scene, frames, out_dir, prefix):
    """Renders `frames` to OUT_DIR/PREFIX_####.png and puts them side by side in
    OUT_DIR/PREFIX_strip.png; returns (seconds per frame, strip path)."""
    seconds, paths = render_frames_timed(scene, frames, out_dir, prefix)
    return seconds, strip(paths, os.path.join(out_dir, prefix + "_strip.png"))


def cpu_seconds():
    """CPU seconds of this process (all threads) and of its waited-for children: a bake runs in
    a job process of its own (addon/jobs/)."""
    import resource
    return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                 resource.getrusage(resource.RUSAGE_CHILDREN)))


def run_op_cpu(op, tag, what):
    """run_op, also returning the CPU time it took, of this process and of the job process it
    ran in: (wall s, CPU s). On a shared machine the CPU time is the steadier measure."""
    c0 = cpu_seconds()
    wall = run_op(op, tag, what)
    return wall, cpu_seconds() - c0


def run_op(op, tag, what):
    """Runs operator `op` (e.g. bpy.ops.plume.bake); exits naming `what` unless it finishes.
    Returns its seconds."""
    t0 = time.perf_counter()
    if op() != {'FINISHED'}:
        sys.exit(f"{tag}: {what} failed")
    return time.perf_counter() - t0


# --- Shared by the toon and flame examples ------------------------------------------------


def flat_box(name, location, size, color, add_primitive=None):
    """A box of `size` (m) at `location`, flat `color` (emission only): e.g. a floor or ceiling
    drawn in a toon picture, or a log under a fire (add_primitive: a bpy.ops.mesh primitive 2 m
    across, e.g. a cylinder); it is no Plume object."""
    if add_primitive is None:
        bpy.ops.mesh.primitive_cube_add(size=1.0, location=location)
    else:
        add_primitive(location=location)
        size = tuple(v / 2.0 for v in size)
    box = bpy.context.active_object
    box.name = name
    box.scale = size
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    emission = nodes.new('ShaderNodeEmission')
    emission.inputs["Color"].default_value = (*color, 1.0)
    mat.node_tree.links.new(emission.outputs[0], nodes["Material Output"].inputs["Surface"])
    box.data.materials.append(mat)
    return box


def shown_frames(fractions, frames):
    """The frames at `fractions` of a shot of `frames` frames (1 .. frames, sorted, once each)."""
    return sorted({max(1, min(frames, round(f * frames))) for f in fractions})


# --- Flow-graph fire (graph_fire_synthesis.txt) ---------------------------------------------

#: RAM a pathline sample takes while the graph is built (pathline_group.h: velocity, density,
#: temperature as floats): the build holds every group of every state, |Ω| L 20 B per node.
PATHLINE_SAMPLE_BYTES = 20


def addon_module(name):
    """A module of the installed add-on, e.g. '_native', 'cache', 'flowgraph', 'snapshot'."""
    import importlib
    return importlib.import_module("plume." + name)


def compat():
    """The add-on's module of Blender version differences (plume.blender_compat)."""
    return addon_module("blender_compat")


def select(objects, active):
    """Selects exactly `objects` and makes `active` the active object."""
    bpy.ops.object.select_all(action='DESELECT')
    for ob in objects:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = active


def fire_domain(name, box, location, resolution, frames, nodes_per_frame, lifetime):
    """A box of `box` (m) centred at `location` made a fire domain recording pathline groups
    (§4.2): one state of a flow graph. All states of a graph share the box, the resolution, the
    fuel Sources, nodes per frame and lifetime t_max. Combustion (eqs. 3-5) gives a flame whose
    hot part is short: strong cooling c (the quartic cooling takes T from T_max to half in
    ~0.1 s); strong vorticity confinement curls it; Mantaflow's faster solver settings
    (MacCormack, trilinear, Euler back-traces, pressure tolerance 1e-3) cost about a quarter of
    Plume's defaults."""
    dom = domain_cube(name, 1.0, location, resolution, frames)
    dom.scale = box
    d = dom.plume.domain
    d.combustion = d.pathlines = True
    d.pathline_nodes_per_frame, d.pathline_lifetime = nodes_per_frame, lifetime
    d.vorticity = 0.8
    d.burn_rate, d.heat_yield, d.soot_yield = 6.0, 6.0, 0.3
    d.cooling_rate, d.max_temperature = 40.0, 4.0
    d.advection, d.interpolation, d.trace = 'MACCORMACK', 'LINEAR', 'EULER'
    d.pressure_tolerance = 1e-3
    if hasattr(d, "flame_vorticity"):  # newer add-ons: pinned off, as the examples were measured
        d.flame_vorticity = 0.0
    return dom


def fire_states(states, box, location, resolution, frames, nodes_per_frame, lifetime, cooling):
    """One fire_domain per (name, vorticity confinement ε) of `states`, all on the same box with
    cooling c = `cooling`: the states of a flow graph, in name order. Returns the domains."""
    domains = []
    for name, vorticity in states:
        dom = fire_domain(name, box, location, resolution, frames, nodes_per_frame, lifetime)
        dom.plume.domain.vorticity, dom.plume.domain.cooling_rate = vorticity, cooling
        domains.append(dom)
    return domains


def fuel_source(name, add_primitive, location, dims, fuel=1.0, temperature=1.0):
    """A mesh primitive (e.g. bpy.ops.mesh.primitive_cylinder_add; 2 m across by default) scaled
    to `dims` (m) at `location`, made a Plume Source of fuel (the fuel-injection region Ω where
    pathlines are seeded; no smoke density: the fire makes its soot), hidden from renders."""
    add_primitive(location=location)
    src = bpy.context.active_object
    src.name = name
    src.scale = tuple(v / 2.0 for v in dims)
    bpy.ops.plume.role_set(role='SOURCE')
    s = src.plume.source
    s.fuel, s.density, s.temperature = fuel, 0.0, temperature
    if hasattr(s, "fuel_noise"):  # newer add-ons: off, the examples key a noise feed of their own
        s.fuel_noise = 0.0
    src.hide_render = True
    return src


def flicker(src, speed, fuel_share, frames, key_every=4, seed=0, along_x=True):
    """Keys a fuel Source's feed with smooth noise over frames 1 .. frames + 1: a key every
    `key_every` frames with a random horizontal velocity within ±`speed` m/s and fuel within
    ±`fuel_share` of itself, drawn independently by a generator seeded with `seed`, Bézier in
    between (the first key is the still, even feed). Nothing repeats: the feed has no period, so
    no group of pathlines recurs by construction and every transition the flow graph finds is a
    similarity of the fire itself (§4.3). Every state of a graph is baked from the same keys:
    Build Flow Graph leaves out each bake's start-up (flowgraph.startup_groups), the only
    stretch where states fed alike look alike. Keys half a puff apart put the feed's energy near
    the puffing rate of a fire (~1.5/√D Hz for a pool fire of diameter D m): give `key_every`
    half the puff period in frames. With `along_x` False the velocity has no x part (a piece of
    a line along x then never pushes its flames into its neighbours'). A log pile does not burn
    evenly: the uneven feed breaks the symmetry of the flame, which then flickers as a fire
    does."""
    import random
    rng = random.Random(seed)
    s = src.plume.source
    fuel = s.fuel
    for frame in range(1, frames + 2, key_every):
        first = frame == 1
        if first:
            s.velocity = (0.0, 0.0, 0.0)
        else:
            vx, vy = rng.uniform(-speed, speed), rng.uniform(-speed, speed)
            s.velocity = (vx if along_x else 0.0, vy, 0.0)
        s.fuel = fuel if first else fuel * (1.0 + rng.uniform(-fuel_share, fuel_share))
        for name in ("velocity", "fuel"):
            src.keyframe_insert("plume.source." + name, frame=frame)
    s.fuel, s.velocity = fuel, (0.0, 0.0, 0.0)
    return src


def bake_fire_states(domains, tag):
    """Bakes every state (with its pathlines.bin); prints per state the bake time (per frame)
    and the pathline file (size, nodes, |Ω|, L, bytes per node), and the size of all their
    groups. Returns the bake seconds per state; exits on failure."""
    native, cache, snapshot = (addon_module(n) for n in ("_native", "cache", "snapshot"))
    seconds, ram = [], 0
    for dom in domains:
        select([dom], dom)
        s, cpu = run_op_cpu(bpy.ops.plume.bake, tag, f"the bake of '{dom.name}'")
        d = dom.plume.domain
        frames = d.frame_end - d.frame_start + 1
        path = cache.pathlines_path(snapshot.cache_folder_of(dom))
        f = native.PathlineFile.open(path)
        lay = f.layout
        node_ram = lay.particles * lay.samples * PATHLINE_SAMPLE_BYTES
        ram += node_ram * f.node_count
        print(f"{tag}: bake '{dom.name}' {frames} frames in {s:.1f} s ({s / frames:.2f} s/frame, "
              f"CPU {cpu / frames:.2f} s/frame); "
              f"pathlines.bin {os.path.getsize(path) / 1e6:.0f} MB: {f.node_count} nodes of "
              f"|Ω| = {lay.particles} pathlines x L = {lay.samples} samples "
              f"({lay.sample_dt * 1e3:.1f} ms apart), {f.bytes_per_node / 1e6:.2f} MB/node on "
              f"disk, {node_ram / 1e6:.2f} MB/node in RAM", flush=True)
        seconds.append(s)
    print(f"{tag}: the states hold {ram / 1e9:.2f} GB of pathline groups (Build Flow Graph "
          "streams them: at most a block of 192 nodes and 32 more in memory)", flush=True)
    return seconds


def build_flow_graph(domains, keeper, tag, block_size=32, min_node_gap=8):
    """Build Flow Graph (plume.flowgraph_build) over the states `domains` (name order), kept
    with `keeper`, B = `block_size`, ε = (2a + b)/3 (§4.3: a, b the cheapest and dearest
    candidate). Prints the graph summary; returns the seconds."""
    select(domains, keeper)
    g = keeper.plume.domain.flowgraph
    g.block_size, g.min_node_gap, g.epsilon = block_size, min_node_gap, 0.0
    seconds = run_op(bpy.ops.plume.flowgraph_build, tag, "Build Flow Graph")
    print(f"{tag}: Build Flow Graph {seconds:.1f} s (B = {block_size}, min node gap "
          f"{min_node_gap}): {g.state_names}; {g.summary}", flush=True)
    return seconds


def key_target_states(dom, keys):
    """Keys the flow graph's target state (§5.1) of `dom`: (frame, state) pairs, held constant
    until the next key."""
    g = dom.plume.domain.flowgraph
    for frame, state in keys:
        g.target_state = state
        g.keyframe_insert("target_state", frame=frame)
    for fc in compat().fcurves(dom):
        if fc.data_path.endswith("target_state"):
            for k in fc.keyframe_points:
                k.interpolation = 'CONSTANT'


def synthesize_fire(dom, frames, tag):
    """Synthesize Fire (plume.fire_synthesize) for frames 1..frames from `dom`'s graph; returns
    (seconds, the fire Volume object); exits on failure."""
    g = dom.plume.domain.flowgraph
    g.frame_start, g.frame_end = 1, frames
    select([dom], dom)
    seconds = run_op(bpy.ops.plume.fire_synthesize, tag, "Synthesize Fire")
    return seconds, bpy.data.objects[g.fire_object]


def hide_bakes(domains):
    """Hides the domains and the Volume objects of their bakes from renders (the synthesized
    fire shows alone)."""
    for dom in domains:
        dom.hide_render = True
        vo = bpy.data.objects.get(dom.plume.domain.volume_object)
        if vo is not None:
            vo.hide_render = True


def png_pixels(path, alpha=False):
    """RGB (h, w, 3), or with `alpha` RGBA (h, w, 4), pixels of an image file, read through
    Blender (rows bottom first)."""
    import numpy as np
    img = bpy.data.images.load(path, check_existing=False)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    px = px.reshape(h, w, 4)
    return px if alpha else px[..., :3]


def lit_share(path, level=0.05):
    """Share of the pixels of PNG `path` brighter than `level` in some channel."""
    return float((png_pixels(path).max(axis=2) > level).mean())


#: Emission strength of the synthesized fire's material in the flow-graph examples (Plume Fire's
#: "Emission Strength" = this × b², the add-on's default 10): the splatted particles average
#: their temperatures, so the synthesized fire burns cooler than the solver's grid and at 10 (the
#: add-on installed for the measurements; 16 in newer ones) read dim brown under AgX; at 25 its
#: core reads orange-yellow (campfire at 64 cells, AgX: the lit
#: share at 320 x 180 from 11.6% to 12.2%, the brightest pixels from 0.76 to 0.92). The material
#: is the artist's to change: this sets a value of it, nothing else.
FLOWGRAPH_FIRE_EMISSION = 25.0


def set_fire_emission(fire, strength):
    """Sets the emission strength factor of `fire`'s Plume Fire material (the Math node feeding
    the Principled Volume's Emission Strength) to `strength`; returns the old value."""
    nt = fire.data.materials[0].node_tree
    for link in nt.links:
        if link.to_socket.name == "Emission Strength" and link.from_node.type == 'MATH':
            old = link.from_node.inputs[1].default_value
            link.from_node.inputs[1].default_value = strength
            return old
    raise RuntimeError(f"no emission strength node in {fire.data.materials[0].name!r}")


def flowgraph_example(tag, usage, default_frames, setup, targets, show, graph,
                      emission=FLOWGRAPH_FIRE_EMISSION):
    """A flow-graph fire example from the command line: OUT_DIR [FRAMES]. setup(scene) builds
    the scene (fuel Sources, keyed once: every state is baked from the same feed; camera) and
    returns the state domains in name order; the look is a 640 x 360 Cycles render on a black
    world through the scene's own view transform (each Blender's default: Filmic in 3.4, AgX in
    4.x/5.x), motion blurred by the fire VDBs' velocity grid. Then the
    .blend is saved to OUT_DIR/TAG.blend, every state is baked, Build Flow Graph (kept with
    state 0; `graph`: the keywords of build_flow_graph), the target state is keyed at the
    (fraction of the shot, state) pairs `targets`, FRAMES frames are synthesized, the
    cost-matrix picture is copied to OUT_DIR/TAG_cost.png, the frames at fractions `show` are
    rendered to OUT_DIR/TAG_####.png and OUT_DIR/TAG_strip.png, and the times are printed.
    The fire material's emission strength is set to `emission` (FLOWGRAPH_FIRE_EMISSION).
    Returns (scene, state 0's domain, the fire Volume object, OUT_DIR)."""
    import shutil
    out_dir, frames = parse_args(usage, default_frames)
    scene = new_scene()
    domains = setup(scene)
    cycles(scene, 640, 360, 64, os.path.join(out_dir, tag + "_"))
    plain_world(scene, (0.002, 0.002, 0.003))
    # Cycles blurs the fire along its velocity grid (m/s) over half a frame, as a film camera.
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    keys = [(max(1, round(f * frames)), state) for f, state in targets]
    scene.frame_start, scene.frame_end = 1, frames
    save_blend(out_dir, tag)
    bake_fire_states(domains, tag)
    keeper = domains[0]
    build_flow_graph(domains, keeper, tag, **graph)
    key_target_states(keeper, keys)
    synth_s, fire = synthesize_fire(keeper, frames, tag)
    print(f"{tag}: Synthesize Fire {frames} frames in {synth_s:.1f} s ("
          f"{synth_s / frames * 1e3:.0f} ms/frame, VDB writing included) -> '{fire.name}'",
          flush=True)
    hide_bakes(domains)
    set_fire_emission(fire, emission)
    bpy.ops.wm.save_mainfile()
    folder = addon_module("snapshot").cache_folder_of(keeper)
    shutil.copyfile(addon_module("flowgraph").image_path(folder),
                    os.path.join(out_dir, tag + "_cost.png"))
    seconds, paths = render_frames_timed(scene, shown_frames(show, frames), out_dir, tag)
    lit = ", ".join(f"{lit_share(p) * 100:.0f}%" for p in paths)
    print(f"{tag}: render {seconds:.1f} s/frame ({scene.render.resolution_x}x"
          f"{scene.render.resolution_y}, {scene.cycles.samples} samples; lit pixels {lit}) -> "
          f"{strip(paths, os.path.join(out_dir, tag + '_strip.png'))}", flush=True)
    return scene, keeper, fire, out_dir

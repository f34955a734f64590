"""The flow-graph fire examples' kit ([Graph Fire Synthesis]): the states' fire domains and
fuel feeds, their bakes, Build Flow Graph, keyed target states, Synthesize Fire, and
flowgraph_example, which runs a whole example from the command line. Scene, render and
strip helpers are scene_kit's."""

import os

import bpy

import scene_kit


def fire_domain(name, box, location, resolution, frames, nodes_per_frame, lifetime):
    """A box of `box` (m) centred at `location` made a fire domain recording pathline groups
    (§4.2): one state of a flow graph. All states of a graph share the box, the resolution, the
    fuel Sources, nodes per frame and lifetime t_max. Combustion (eqs. 3-5) gives a flame whose
    hot part is short: strong cooling c (the quartic cooling takes T from T_max to half in
    ~0.1 s); strong vorticity confinement curls it; Mantaflow's faster solver settings
    (MacCormack, trilinear, Euler back-traces, pressure tolerance 1e-3) cost about a quarter of
    Plume's defaults."""
    dom = scene_kit.domain_cube(name, 1.0, location, resolution, frames)
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
    native, cache, snapshot = (scene_kit.addon_module(n) for n in ("_native", "cache", "snapshot"))
    seconds, ram = [], 0
    for dom in domains:
        scene_kit.select([dom], dom)
        s, cpu = scene_kit.run_op_cpu(bpy.ops.plume.bake, tag, f"the bake of '{dom.name}'")
        d = dom.plume.domain
        frames = d.frame_end - d.frame_start + 1
        path = cache.pathlines_path(snapshot.cache_folder_of(dom))
        f = native.PathlineFile.open(path)
        lay = f.layout
        node_ram = lay.particles * lay.samples * scene_kit.PATHLINE_SAMPLE_BYTES
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
    scene_kit.select(domains, keeper)
    g = keeper.plume.domain.flowgraph
    g.block_size, g.min_node_gap, g.epsilon = block_size, min_node_gap, 0.0
    seconds = scene_kit.run_op(bpy.ops.plume.flowgraph_build, tag, "Build Flow Graph")
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
    for fc in scene_kit.compat().fcurves(dom):
        if fc.data_path.endswith("target_state"):
            for k in fc.keyframe_points:
                k.interpolation = 'CONSTANT'


def synthesize_fire(dom, frames, tag):
    """Synthesize Fire (plume.fire_synthesize) for frames 1..frames from `dom`'s graph; returns
    (seconds, the fire Volume object); exits on failure."""
    g = dom.plume.domain.flowgraph
    g.frame_start, g.frame_end = 1, frames
    scene_kit.select([dom], dom)
    seconds = scene_kit.run_op(bpy.ops.plume.fire_synthesize, tag, "Synthesize Fire")
    return seconds, bpy.data.objects[g.fire_object]


def hide_bakes(domains):
    """Hides the domains and the Volume objects of their bakes from renders (the synthesized
    fire shows alone)."""
    for dom in domains:
        dom.hide_render = True
        vo = bpy.data.objects.get(dom.plume.domain.volume_object)
        if vo is not None:
            vo.hide_render = True


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
    out_dir, frames = scene_kit.parse_args(usage, default_frames)
    scene = scene_kit.new_scene()
    domains = setup(scene)
    scene_kit.cycles(scene, 640, 360, 64, os.path.join(out_dir, tag + "_"))
    scene_kit.plain_world(scene, (0.002, 0.002, 0.003))
    # Cycles blurs the fire along its velocity grid (m/s) over half a frame, as a film camera.
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    keys = [(max(1, round(f * frames)), state) for f, state in targets]
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, tag)
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
    folder = scene_kit.addon_module("snapshot").cache_folder_of(keeper)
    shutil.copyfile(scene_kit.addon_module("flowgraph").image_path(folder),
                    os.path.join(out_dir, tag + "_cost.png"))
    shown = scene_kit.shown_frames(show, frames)
    seconds, paths = scene_kit.render_frames_timed(scene, shown, out_dir, tag)
    lit = ", ".join(f"{scene_kit.lit_share(p) * 100:.0f}%" for p in paths)
    print(f"{tag}: render {seconds:.1f} s/frame ({scene.render.resolution_x}x"
          f"{scene.render.resolution_y}, {scene.cycles.samples} samples; lit pixels {lit}) -> "
          f"{scene_kit.strip(paths, os.path.join(out_dir, tag + '_strip.png'))}", flush=True)
    return scene, keeper, fire, out_dir

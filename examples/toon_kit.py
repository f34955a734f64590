"""Shared pieces of the toon-smoke examples ([Cartoon Smoke]), run inside Blender: the flat
toon look in Cycles, Sources that blow a burst, the toon settings the examples share (puffs),
the bake and Build Toon Smoke through the artist's operators, and the render of a few frames
into a strip with the times. Builds on scene_kit. Imported by the examples in examples/toon/::

    HERE = os.path.dirname(os.path.abspath(__file__))
    sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/
    import toon_kit
"""

import sys

import bpy

import scene_kit


def toon_look(scene, background, width, height, samples, filepath):
    """Cycles set up for flat toon colours: the Standard view transform (Filmic would grey the
    flat colours), a plain world of colour `background` and no lights (the toon material is
    emission only)."""
    scene_kit.cycles(scene, width, height, samples, filepath)
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    scene_kit.plain_world(scene, background)


def bake_toon(dom, tag):
    """Bake, then Build Toon Smoke (plume.toon_build, the artist's button) on domain `dom`; the
    domain box and its Volume object are hidden from renders so only the billboards show, and
    the .blend is saved. Returns (bake seconds, build seconds); exits on failure."""
    bpy.context.view_layer.objects.active = dom
    bake_s = scene_kit.run_op(bpy.ops.plume.bake, tag, "the bake")
    build_s = build_toon(dom, tag)
    for ob in (dom, bpy.data.objects.get(dom.plume.domain.volume_object)):
        if ob is not None:
            ob.hide_render = True
    bpy.ops.wm.save_mainfile()
    return bake_s, build_s


def build_toon(dom, tag):
    """Build Toon Smoke on `dom` again (e.g. after changing its toon settings), checks that the
    compositor's result is the "Plume Depth Differences" group's image (so the rendered and saved
    frames carry the outlines); returns the seconds."""
    bpy.context.view_layer.objects.active = dom
    seconds = scene_kit.run_op(bpy.ops.plume.toon_build, tag, "Build Toon Smoke")
    scene = bpy.context.scene
    tree = scene_kit.compat().compositor_tree(scene)
    result = scene_kit.compat().compositor_output(tree) if tree is not None else None
    link = result.links[0] if result is not None and result.is_linked else None
    if not (scene.render.use_compositing and link is not None
            and link.from_node.type == 'GROUP'
            and link.from_node.node_tree.name == "Plume Depth Differences"):
        sys.exit(f"{tag}: the compositor's result is not the outline group's image")
    return seconds


def puffs(t, emission_count, sizes, densities, death_density, depth_threshold,
          birth_density=0.3, birth_spacing=0.8):
    """The toon settings `t` (obj.plume.domain.toon) the examples share: `emission_count`
    particles per frame at the Sources (§2.1) and new ones born where the smoke is denser than
    `birth_density` (§2.3) at least `birth_spacing` stencil sizes from any other, so they stay
    puffs (a particle born in every dense cell merges into one smooth blob); puffy stencil of
    diameter sizes[0]..sizes[1] over the density ramp densities[0]..[1], ρ_death, γ. Sizes
    change by at most a quarter of the largest per frame; a slight stretch."""
    t.emission_count = emission_count
    t.birth_density, t.birth_spacing = birth_density, birth_spacing
    t.death_density = death_density
    t.ramp_density_low, t.ramp_density_high = densities
    t.size_low, t.size_high = sizes
    t.max_size_change = 0.25
    t.stretch_factor = 0.1
    t.stencil = 'PUFFY'
    t.depth_threshold = depth_threshold


def sphere_source(name, radius, location, density=1.0, temperature=0.0,
                  velocity=(0.0, 0.0, 0.0)):
    """A UV sphere made a Plume Source (hidden from renders) with these settings."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, location=location)
    src = bpy.context.active_object
    src.name = name
    bpy.ops.plume.role_set(role='SOURCE')
    s = src.plume.source
    s.density, s.temperature, s.velocity = density, temperature, velocity
    s.smoke_noise = 0.0  # the paper's even sources (the figures were tuned before Breakup)
    src.hide_render = True
    return src


def burst(src, frames_on):
    """Keyframes the source's density, temperature and velocity (constant interpolation): as set
    on frames 1..frames_on, 0 from frames_on + 1 on - a short burst of smoke."""
    s = src.plume.source
    on, off = (s.density, s.temperature, tuple(s.velocity)), (0.0, 0.0, (0.0, 0.0, 0.0))
    for frame, (density, temperature, velocity) in ((1, on), (frames_on + 1, off)):
        s.density, s.temperature, s.velocity = density, temperature, velocity
        for name in ("density", "temperature", "velocity"):
            src.keyframe_insert("plume.source." + name, frame=frame)
    s.density, s.temperature, s.velocity = on
    for fc in scene_kit.compat().fcurves(src):
        for k in fc.keyframe_points:
            k.interpolation = 'CONSTANT'
    return src


def toon_summary(tag, grid, frames, bake_s, build_s, dom, render_s, strip_path):
    """Prints a toon example's times (bake, Build Toon Smoke, render per frame) and its strip."""
    scene = bpy.context.scene
    particles = len(bpy.data.objects[dom.plume.domain.toon.object_name].data.vertices)
    print(f"{tag}: {frames} frames at {grid}, bake {bake_s:.1f} s ({bake_s / frames:.2f} "
          f"s/frame), Build Toon Smoke {build_s:.1f} s, {particles} particles on frame "
          f"{scene.frame_current}, render {render_s:.1f} s/frame ({scene.render.resolution_x}x"
          f"{scene.render.resolution_y}, {scene.cycles.samples} samples) -> {strip_path}",
          flush=True)


def toon_example(tag, usage, default_frames, setup, show, grid):
    """A toon example from the command line: OUT_DIR [FRAMES]; setup(scene, frames, out_dir)
    builds the scene (sources, domain, camera, look) and returns the domain; then the .blend is
    saved to OUT_DIR/TAG.blend, baked, Build Toon Smoke runs, the frames at fractions `show` of
    the shot are rendered to OUT_DIR/TAG_####.png and OUT_DIR/TAG_strip.png, and the times are
    printed (`grid` names the grid in the summary)."""
    out_dir, frames = scene_kit.parse_args(usage, default_frames)
    scene = scene_kit.new_scene()
    dom = setup(scene, frames, out_dir)
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, tag)
    bake_s, build_s = bake_toon(dom, tag)
    render_s, strip_path = scene_kit.render_strip(scene, scene_kit.shown_frames(show, frames),
                                                  out_dir, tag)
    toon_summary(tag, grid, frames, bake_s, build_s, dom, render_s, strip_path)

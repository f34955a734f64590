"""The flow-graph fire manual's recipe "a long campfire from three short simulations", steps
1-10 (step 11, the render, is the artist's F12): a burner made a fuel Source; a box made a fire
domain that records pathlines, its air stirred; two copies of it, so three states on one box,
each with a Seed of its own (its own feed: the burner's Flicker and the stirring differ per
state); the three bakes; Build Flow Graph; Synthesize Fire for longer than the three bakes
together; only the synthesized fire rendered, the camera, a black world, the film's exposure.
`blender_tests/test_recipe_campfire_long.py` performs it and checks the fire;
`bash .ci/screenshots` saves its panel pictures. See examples/recipe_kit.py."""

import bpy

from recipe_kit import Shot, dark_view, new_file, press

BURNER = dict(radius=0.1, depth=0.05, location=(0.0, 0.0, 0.025))
#: The box: a 1 m cube squeezed to 0.6 x 0.6 x 1 m over the burner, its floor at z = 0.
BOX = dict(size=1.0, location=(0.0, 0.0, 0.5), scale=(0.6, 0.6, 1.0))
RESOLUTION = 40                # cells along the box's height: 24 x 24 x 40, 2.5 cm cells
FRAME_END = 72                 # each state: 3 s
#: Forces › Turbulence (m/s²): stirs the air so the flames sway and lean; seeded by each state's
#: Seed, so it is part of each state's own feed. 0 (the fire's default) gives a straight soft
#: column in the synthesis; 8 bends the flames over and, measured, leaves the walk in one state.
TURBULENCE = 3.0
NODES_PER_FRAME = 2
LIFETIME = 0.3                 # s: a state's bake is 10 lifetimes long
#: (name, Seed): names sort in the order of the states.
STATES = (("Fire A", 0), ("Fire B", 1), ("Fire C", 2))
#: Flow-Graph Fire › Block Size 4 and Min Node Gap 20 (defaults 32 and 8): a graph of three
#: 3-second states has 354 nodes. Measured over 20 walks of 240 frames on these bakes: B = 32
#: keeps 67 transitions, no walk reaches all three states and 5 repeat themselves exactly; B = 4
#: with a gap of 20 keeps 1,612 and 1 walk in 20 repeats. Without the Turbulence, B = 8 with a
#: gap of 8 looped on a few groups in 11 of 20 walks, B = 4 with a gap of 20 in none.
BLOCK_SIZE = 4
MIN_NODE_GAP = 20
SYNTH_END = 240                # 10 s of fire from three 3 s bakes
FILM_EXPOSURE = 3.0            # Render Properties › Film › Exposure: median lit 0.39-0.58
CAMERA_LOCATION, CAMERA_ROTATION_DEG, LENS = (0.0, -2.0, 0.4), (90.0, 0.0, 0.0), 50.0

OPEN_STATE = ("PHYSICS_PT_plume_forces", "PHYSICS_PT_plume_combustion")
OPEN_GRAPH = ("PHYSICS_PT_plume_flowgraph",)


def select(objects, active):
    bpy.ops.object.select_all(action='DESELECT')
    for ob in objects:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = active


def steps(cache_dir):
    """Yields the recipe's Shots; returns (the three state domains, the synthesized fire)."""
    yield from new_file()                                   # 1. File › New › General, no cube
    press(bpy.ops.mesh.primitive_cylinder_add, **BURNER)    # 2. the burner: a fuel Source
    burner = bpy.context.view_layer.objects.active
    burner.name = "Burner"
    press(bpy.ops.plume.role_set, role='SOURCE')
    s = burner.plume.source
    s.fuel, s.density = 1.0, 0.0
    burner.hide_render = True
    press(bpy.ops.mesh.primitive_cube_add, **BOX)           # 3. the box: a domain
    dom = bpy.context.view_layer.objects.active
    press(bpy.ops.plume.role_set, role='DOMAIN')
    d = dom.plume.domain
    d.resolution, d.frame_end = RESOLUTION, FRAME_END       #    Settings
    d.cache_directory = cache_dir
    d.combustion = True                                     # 4. Combustion, Turbulence,
    d.turbulence = TURBULENCE                               #    Record Pathlines
    d.pathlines = True
    d.pathline_nodes_per_frame, d.pathline_lifetime = NODES_PER_FRAME, LIFETIME
    yield Shot("ui_campfire_long_domain.png", open=OPEN_STATE, scroll=300)
    domains = [dom]                                         # 5. two copies: Shift+D, Enter
    for _ in STATES[1:]:
        press(bpy.ops.object.duplicate_move, TRANSFORM_OT_translate=dict(value=(0.0, 0.0, 0.0)))
        domains.append(bpy.context.view_layer.objects.active)
    for ob, (name, seed) in zip(domains, STATES):           # 5. named; 6. a Seed each
        ob.name = name
        ob.plume.domain.seed = seed
    for ob in domains:                                      # 7. bake each state
        select([ob], ob)
        press(bpy.ops.plume.bake)
    keeper = domains[0]                                     # 8. the three selected, Fire A
    select(domains, keeper)                                 #    active: Build Flow Graph
    g = keeper.plume.domain.flowgraph
    g.block_size, g.min_node_gap = BLOCK_SIZE, MIN_NODE_GAP
    press(bpy.ops.plume.flowgraph_build)
    g.frame_end = SYNTH_END                                 # 9. End 240, Synthesize Fire
    press(bpy.ops.plume.fire_synthesize)
    yield Shot("ui_campfire_long_graph.png", open=OPEN_GRAPH, scroll=1600)
    for ob in domains:                                      # 10. the bakes' volumes off in
        vo = bpy.data.objects.get(ob.plume.domain.volume_object)   # renders; camera, world,
        if vo is not None:                                  #     Cycles, exposure
            vo.hide_render = True
    dark_view(CAMERA_LOCATION, CAMERA_ROTATION_DEG, LENS)
    scene = bpy.context.scene
    scene.cycles.film_exposure = FILM_EXPOSURE
    scene.frame_end = SYNTH_END
    return domains, bpy.data.objects[g.fire_object]

"""A domain's properties (``obj.plume.domain``): its grid bake (solver, combustion, cache), the
streak surfaces it traces and builds ([Smoke Surfaces]), the pathlines it records, and the
toon and flow-graph settings it holds."""

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, PointerProperty, StringProperty)

from ..flame_smoke import SMOKE_POINT
from ..ranges import RANGES, text
from .flowgraph import PlumeFlowGraphSettings
from .toon import PlumeToonSettings

BOUNDARY_ITEMS = (
    ('OPEN', "Open", "Air: smoke and air flow out freely (p = 0)"),
    ('CLOSED', "Closed", "Wall: no flow through this side"),
)


def is_gas_domain(ob):
    """True for an object with a Blender fluid modifier that is a Gas domain (Mantaflow smoke)."""
    return ob is not None and any(
        m.type == 'FLUID' and m.fluid_type == 'DOMAIN' and m.domain_settings is not None
        and m.domain_settings.domain_type == 'GAS' for m in ob.modifiers)


#: Vorticity confinement ε of a smoke domain, and of a fire (Combustion on). Plume's ε is
#: physical (f = ε Δx (N × ω), Δx in metres), so a smoke's 0.2 leaves a fire a laminar cone: on
#: a 0.3 m burner at 64 cells ε 0.2-2 gave a smooth cone, 4-10 flickering tongues; 6 is the
#: fire's default. Flame Vorticity adds more where the fuel burns, and the Source's Flicker breaks
#: the burner's symmetry (examples/smoke/fire_vs_mantaflow.py).
SMOKE_VORTICITY = 0.2
#: Turbulence of a smoke domain, m/s²: enough to fold a 2 m domain's plume into sheets.
SMOKE_TURBULENCE = 2.0
FIRE_VORTICITY = 6.0


def _combustion_changed(settings, context):
    """Turning Combustion on swaps the smoke's default vorticity and turbulence for the fire's
    (off: back), unless the artist set their own."""
    if settings.combustion and abs(settings.vorticity - SMOKE_VORTICITY) < 1e-6:
        settings.vorticity = FIRE_VORTICITY
    elif not settings.combustion and abs(settings.vorticity - FIRE_VORTICITY) < 1e-6:
        settings.vorticity = SMOKE_VORTICITY
    if settings.combustion and abs(settings.turbulence - SMOKE_TURBULENCE) < 1e-6:
        settings.turbulence = 0.0
    elif not settings.combustion and settings.turbulence == 0.0:
        settings.turbulence = SMOKE_TURBULENCE


def _boundary(side, default='OPEN'):
    return EnumProperty(name=side, items=BOUNDARY_ITEMS, default=default,
                        description=f"Boundary condition of the domain's {side} side")


class PlumeDomainSettings(bpy.types.PropertyGroup):
    # --- Settings ---
    resolution: IntProperty(
        name="Resolution", default=32, soft_min=8, soft_max=512,
        description="Cells along the longest axis of the domain (Δx = longest side / resolution); "
                    f"validated at bake time to {text('resolution')}")
    adaptive_domain: BoolProperty(
        name="Adaptive Domain", default=False,
        description="Simulate only the box around the smoke, heat and fuel, grown and shrunk every "
                    "step; outside it the air is at rest and at ambient temperature. The cache "
                    "stays in place (as Mantaflow's Adaptive Domain)")
    adaptive_margin: IntProperty(
        name="Margin", default=6, min=RANGES["adaptive_margin"][0], max=RANGES["adaptive_margin"][1],
        description="Cells of air kept around the smoke in the adaptive box; more follows the "
                    "air the plume sets moving more closely (Mantaflow's Adaptive Domain › "
                    "Margin)")
    adaptive_threshold: FloatProperty(
        name="Threshold", default=0.005, min=RANGES["adaptive_threshold"][0],
        max=RANGES["adaptive_threshold"][1], precision=4,
        description="Density, heat |T - T_amb|, fuel or soot above which a cell counts as smoke "
                    "for the adaptive box (Mantaflow's Adaptive Domain › Threshold)")
    frame_start: IntProperty(name="Start", default=1, description="First frame of the bake")
    frame_end: IntProperty(name="End", default=50, description="Last frame of the bake")
    time_scale: FloatProperty(
        name="Time Scale", default=1.0, soft_min=0.0, soft_max=10.0,
        description="Simulated seconds per real second: Δt_frame = time scale / scene fps")
    substeps: IntProperty(name="Substeps", default=1, soft_min=1, soft_max=20,
                          description="Minimum fractional steps (Stam 1999) per frame")
    use_cfl: BoolProperty(name="Adaptive Steps", default=True,
                          description="Add steps so that no cell moves more than the CFL number per step")
    cfl: FloatProperty(name="CFL", default=4.0, soft_min=0.5, soft_max=10.0,
                       description="CFL number: cells the fastest flow may cross in one step")
    seed: IntProperty(name="Seed", default=0, soft_min=0,
                      description="Seed of every random choice: same seed, same bake")
    threads: IntProperty(name="Threads", default=0, soft_min=0, soft_max=64,
                         description="Worker threads (0 = all cores); results do not depend on it")
    # --- Forces (Fedkiw, Stam & Jensen 2001) ---
    alpha: FloatProperty(
        name="Density Buoyancy (α)", default=1.0, soft_min=-10.0, soft_max=10.0,
        description="α: buoyancy from density, f = -g (α ρ + β (T - T_amb)) (Fedkiw 2001 eq. 8); "
                    "> 0 makes dense smoke rise, as in Blender")
    beta: FloatProperty(
        name="Heat Buoyancy (β)", default=1.0, soft_min=-10.0, soft_max=10.0,
        description="β: buoyancy from temperature, f = -g (α ρ + β (T - T_amb)) (Fedkiw 2001 eq. 8)")
    buoyancy_units: EnumProperty(
        name="Buoyancy Units", default='PHYSICAL',
        description="What α and β mean: Plume's physical units, or Mantaflow's (a scene moved "
                    "from a Mantaflow domain keeps its α and β and rises as high)",
        items=(('PHYSICAL', "Physical", "f = -g (α ρ + β (T - T_amb)): α = 1 lifts smoke of "
                                        "density 1 with the acceleration g"),
               ('MANTAFLOW', "Mantaflow", "α and β as in Mantaflow's Density and Heat: its "
                                          "buoyancy is g α ρ / L, L the domain's longest side "
                                          "in metres, so Plume bakes with α / L and β / L")))
    ambient_temperature: FloatProperty(
        name="Ambient Temperature", default=0.0, soft_min=-10.0, soft_max=10.0,
        description="T_amb: temperature of the surrounding air (T_0 of the fire paper)")
    gravity: FloatVectorProperty(
        name="Gravity", size=3, default=(0.0, 0.0, -9.81), subtype='ACCELERATION', unit='ACCELERATION',
        description="g: gravity; buoyancy acts against it (Fedkiw 2001 eq. 8)")
    vorticity: FloatProperty(
        name="Vorticity (ε)", default=SMOKE_VORTICITY, soft_min=0.0, soft_max=10.0,
        description="ε: vorticity confinement strength (Fedkiw 2001 eq. 11); "
                    f"{SMOKE_VORTICITY:g} for smoke, {FIRE_VORTICITY:g} once Combustion is "
                    "turned on (a fire curls into tongues)")
    wind: FloatVectorProperty(
        name="Wind", size=3, default=(0.0, 0.0, 0.0), subtype='VELOCITY', unit='VELOCITY',
        description="u_wind: velocity the air is pulled towards, m/s")
    wind_strength: FloatProperty(
        name="Wind Strength", default=0.0, soft_min=0.0, soft_max=10.0,
        description="k_w: f_wind = k_w (u_wind - u), 1/s")
    turbulence: FloatProperty(
        name="Turbulence", default=SMOKE_TURBULENCE, min=0.0, soft_max=20.0, unit='ACCELERATION',
        description="Strength of a slowly drifting swirl in the air, as a room's draughts give "
                    "real smoke: an even plume leans, folds and curls instead of rising as a "
                    "straight column (0: still air). "
                    f"{SMOKE_TURBULENCE:g} for smoke, 0 once Combustion is turned on (a fire "
                    "stirs its own air: Flame Vorticity)")
    turbulence_scale: FloatProperty(
        name="Turbulence Size", default=0.4, min=1e-4, soft_min=0.01, soft_max=5.0,
        unit='LENGTH', description="Size of the turbulence's swirls")
    turbulence_rate: FloatProperty(
        name="Turbulence Speed", default=0.5, min=0.0, soft_max=10.0,
        description="How many times a second the turbulence's swirls change")
    density_dissipation: FloatProperty(
        name="Dissipation", default=0.0, soft_min=0.0, soft_max=1.0,
        description="Fraction of the smoke density lost per second")
    # --- Advection ---
    advection: EnumProperty(
        name="Advection", default='BFECC',
        description="How the smoke, heat and velocity are carried along the flow each step",
        items=(('SEMI_LAGRANGIAN', "Semi-Lagrangian", "Stable first-order backtrace (Stam 1999)"),
               ('BFECC', "BFECC", "Back and forth error compensation (Kim et al. 2005, "
                                  "as in the Smoke Surfaces paper): sharper detail"),
               ('MACCORMACK', "MacCormack", "Selle et al. 2008: BFECC's accuracy with two passes "
                                            "instead of three (faster)")))
    interpolation: EnumProperty(
        name="Interpolation", default='MONOTONIC_CUBIC',
        description="How the grid is sampled between cells when it is carried along the flow",
        items=(('LINEAR', "Linear", "Trilinear sampling"),
               ('MONOTONIC_CUBIC', "Monotonic Cubic", "Monotonic cubic sampling (Fedkiw 2001 eq. 12-13): "
                                                      "keeps small rolling features, no new extrema")))
    linear_velocity: BoolProperty(
        name="Fast Velocity", default=True,
        description="Carry the velocity with trilinear samples (the smoke, heat and fuel keep the "
                    "Interpolation above): with BFECC a step about 2x cheaper and nearly as "
                    "sharp; off, the velocity is carried with the Interpolation too (other "
                    "small-scale motion, not more of it)")
    trace: EnumProperty(
        name="Back-trace", default='MIDPOINT',
        description="How far back each cell looks for what the flow brings it (Stam 1999 §3.2)",
        items=(('MIDPOINT', "Midpoint", "Explicit midpoint rule (RK2): second order in time, "
                                        "follows curved flow more closely"),
               ('EULER', "Euler", "One step with the velocity at the cell itself: first order, "
                                  "no interpolation, faster (Mantaflow's default)")))
    conserve_mass: BoolProperty(
        name="Conserve Mass", default=True,
        description="Restore the total smoke and heat after each advection, less what left "
                    "through open sides (advection alone drifts 5-50% in 100 steps)")
    # --- Pressure ---
    pressure_tolerance: FloatProperty(
        name="Tolerance", default=1e-4, soft_min=1e-8, soft_max=0.1, precision=6,
        description="Relative residual |r|/|b| at which the pressure solve (MGPCG) stops")
    max_pressure_iterations: IntProperty(
        name="Max Iterations", default=200, soft_min=1, soft_max=2000,
        description="Most conjugate gradient iterations per pressure solve")
    # --- Boundaries: sides -x, +x, -y, +y, -z, +z ---
    boundary_neg_x: _boundary("-X")
    boundary_pos_x: _boundary("+X")
    boundary_neg_y: _boundary("-Y")
    boundary_pos_y: _boundary("+Y")
    boundary_neg_z: _boundary("-Z (floor)", default='CLOSED')
    boundary_pos_z: _boundary("+Z")
    # --- Combustion ([Graph Fire Synthesis] eqs. 1-5) ---
    combustion: BoolProperty(name="Combustion", default=False, update=_combustion_changed,
                             description="Burn fuel into heat and soot: the domain becomes a fire "
                                         f"simulation (Vorticity {SMOKE_VORTICITY:g} becomes "
                                         f"{FIRE_VORTICITY:g}, Turbulence {SMOKE_TURBULENCE:g} becomes 0)")
    burn_rate: FloatProperty(name="Burn Rate (r)", default=1.5, soft_min=0.0, soft_max=20.0,
                             description="r: fuel burnt per second, dF/dt = -r F (eq. 3)")
    soot_yield: FloatProperty(name="Soot Yield (k_S)", default=0.5, soft_min=0.0, soft_max=5.0,
                              description="k_S: soot made per unit of fuel burnt (eq. 4)")
    heat_yield: FloatProperty(name="Heat Yield (k_T)", default=6.0, soft_min=0.0, soft_max=20.0,
                              description="k_T: heat made per unit of fuel burnt (eq. 5)")
    conductivity: FloatProperty(name="Conductivity (κ)", default=0.0, soft_min=0.0, soft_max=1.0,
                                description="κ: thermal conductivity (heat diffusion), m²/s (eq. 5)")
    cooling_rate: FloatProperty(
        name="Cooling (c)", default=8.0, soft_min=0.0, soft_max=10.0,
        description="c: cooling c ((T - T_0)/(T_max - T_0))^4 per second (eq. 5)")
    max_temperature: FloatProperty(name="Max Temperature (T_max)", default=3.0, soft_min=0.0,
                                   soft_max=20.0, description="T_max: temperature of the hottest flame (eq. 5)")
    expansion: FloatProperty(
        name="Expansion (φ)", default=3.0, soft_min=0.0, soft_max=10.0,
        description="φ: divergence per unit of fuel burnt per second in the reaction zone (eq. 1)")
    flame_vorticity: FloatProperty(
        name="Flame Vorticity", default=24.0, soft_min=0.0, soft_max=100.0,
        description="Swirl added where fuel burns, on top of Vorticity: the flames curl into "
                    "licking tongues while the smoke above them stays smooth (as Mantaflow's "
                    "Flame Vorticity: its 0.5 at 24 fps is about 12 here)")
    # --- Flame Smoke ([Structural Flames] §6.3, flame_smoke.py) ---
    flame_smoke: BoolProperty(
        name="Flame Smoke", default=False,
        description="Emit smoke above every baked structural flame (Bake Flames first): at the "
                    "smoke point h above its tip, with its tip's velocity, as much as its "
                    "radiation (eq. 5) times Smoke Yield, hot enough to rise as the flames do")
    flame_smoke_yield: FloatProperty(
        name="Smoke Yield", default=10.0, min=0.0, soft_max=1000.0,
        description="The paper's arbitrary scale factor: smoke mass (density × m³) per second "
                    "per unit of flame energy E (eq. 5); 10 gives a torch's flames (E ~ 1e-4) "
                    "smoke of density ~1 at the smoke points")
    flame_smoke_point: FloatProperty(
        name="Smoke Point", default=SMOKE_POINT, soft_min=0.0, soft_max=2.0, unit='LENGTH',
        description="The minimum laminar flame height at which smoke first escapes from "
                    "the flame tip (m): flames shorter than this (|tip − base|) emit no smoke. "
                    f"The default, {SMOKE_POINT:g} m, keeps candles clean and lets torches' and "
                    "campfires' tall flames smoke (fuels' smoke points: ~0.02 m kerosene to "
                    "~0.16 m propane); 0: every flame smokes; >= 0")
    flame_smoke_temperature: FloatProperty(
        name="Smoke Temperature", default=0.0, soft_min=0.0, soft_max=10.0,
        description="Temperature of the smoke above ambient; 0 = automatic: the temperature "
                    "whose buoyancy β |g| (T − T_amb) equals the flames' eq. 2 buoyancy")
    # --- Streak surfaces ([Smoke Surfaces] §3.2-3.4) ---
    pathlines: BoolProperty(
        name="Record Pathlines", default=False,
        description="Record pathline groups during this fire bake for Flow-Graph Fire: "
                    "particles seeded in the fuel cells every node step and followed over their "
                    "lifetime (Graph-based Fire Synthesis paper)")
    pathline_nodes_per_frame: IntProperty(
        name="Nodes per Frame", default=4, min=RANGES["pathline_nodes_per_frame"][0],
        max=RANGES["pathline_nodes_per_frame"][1],
        description="Node steps per frame (Δt_n = frame / this). The synthesis reproduces the "
                    "bake best when the fastest particles cross about one cell per node step "
                    "(§4.1: Δt = 0.5 Δx / U); memory grows with its square")
    pathline_lifetime: FloatProperty(
        name="Lifetime (t_max)", default=1.0, min=0.01, soft_max=5.0, unit='TIME_ABSOLUTE',
        description="t_max: how long each pathline is followed, long enough for the fire "
                    "particles to dissipate (§4.3)")
    pathline_float16: BoolProperty(
        name="Half Precision", default=False,
        description="Store the pathline samples as 16-bit floats (half the file size)")
    streaks: BoolProperty(
        name="Streak Surfaces", default=False,
        description="Trace particles from the Sources' point sources during the bake, for "
                    "Streak Surfaces › Build Surfaces")
    emission_period: IntProperty(
        name="Emission Period", default=1, soft_min=1, soft_max=20,
        description="Steps between two particles of a point source (§3.2: one every step)")
    max_streaklines: IntProperty(
        name="Max Streaklines", default=256, soft_min=0, soft_max=4096,
        description="At most this many streaklines over all Sources: Point Sources per source "
                    "cell are thinned at random (seeded, in proportion to each Source) down to "
                    "it. The paper's sheets use 11-20 streaklines; a large source at 16 per cell "
                    "gives thousands, which cluster into one ragged sheet. 0 keeps them all")
    motion_source: EnumProperty(
        name="Motion", default='PLUME',
        items=(('PLUME', "Plume Simulation", "Simulate the smoke with Plume and trace its velocity"),
               ('MANTAFLOW', "Mantaflow Cache",
                "Trace the velocity of an existing Blender Mantaflow gas bake (OpenVDB cache) "
                "instead of simulating; the volume frames hold the Mantaflow density, and "
                "the streak surfaces and toon smoke follow its velocity")),
        description="What moves the streak and toon particles: any smoke simulation's velocity "
                    "will do, Plume's own or a Mantaflow bake")
    mantaflow_domain: PointerProperty(
        name="Mantaflow Domain", type=bpy.types.Object, poll=lambda _self, ob: is_gas_domain(ob),
        description="Blender fluid domain (type Gas, adaptive domain off) whose OpenVDB cache, "
                    "baked over this domain's frame range, moves the particles when Motion is "
                    "Mantaflow Cache")
    streak_threshold: FloatProperty(
        name="Threshold (h0)", default=0.0, soft_min=0.0, soft_max=100.0, precision=4,
        description="h0: streaklines with h(α,β) < h0 share a surface (§3.3); 0 = the default, "
                    "the mean of h in each candidate group")
    density_k_u: IntProperty(
        name="Sampling u (k_u)", default=4, soft_min=0, soft_max=16,
        description="k_u: density samples between particles along a streakline (§3.4, Figure 8)")
    density_k_v: IntProperty(
        name="Sampling v (k_v)", default=2, soft_min=0, soft_max=16,
        description="k_v: density samples between neighbouring streaklines (§3.4, Figure 8)")
    sheet_falloff: EnumProperty(
        name="Contour", default='EXP',
        items=(('EXP', "e^(-|n·v|)", "p = d e^(-|n·v|), the paper's choice (§3.4)"),
               ('LINEAR', "1 - |n·v|", "p = d (1 - |n·v|), the simple attenuation of §3.4")),
        description="How the angle between normal n and view v shapes the opacity p (§3.4)")
    sheet_shading: EnumProperty(
        name="Shading", default='EMISSION',
        items=(('EMISSION', "Emission",
                "The paper's model: the sheets glow with their colour and Brightness whatever "
                "the lights, so the smoke reads the same in any scene"),
               ('LIT', "Lit",
                "The sheets take their light from the scene's lamps and world, as a thin "
                "translucent film: bright on the side facing a lamp, glowing through on the "
                "other, casting soft shadows; Brightness is not used")),
        description="Where the smoke sheets' light comes from (Build Surfaces again to apply)")
    sheet_color: FloatVectorProperty(
        name="Sheet Color", size=4, subtype='COLOR', default=(0.85, 0.85, 0.9, 1.0), min=0.0,
        max=1.0, description="Colour of the smoke sheets")
    sheet_brightness: FloatProperty(
        name="Brightness", default=1.0, soft_min=0.0, soft_max=10.0,
        description="Emission strength of the smoke sheets")
    sheet_opacity: FloatProperty(
        name="Opacity Scale", default=1.0, soft_min=0.0, soft_max=10.0,
        description="Multiplies the density d in p = d e^(-|n·v|)")
    surfaces_collection: StringProperty(
        name="Surfaces", default="", description="Collection holding this domain's streak surfaces")
    # --- Cache ---
    cache_directory: StringProperty(
        name="Cache", subtype='DIR_PATH', default="//plume_cache/",
        description="Folder of the bake; a sub-folder named after the domain holds its files "
                    "('//' = next to the .blend, or the working directory when unsaved)")
    volume_object: StringProperty(name="Volume Object", default="",
                                  description="Name of the Volume object showing this domain's bake")
    frames_baked: IntProperty(name="Frames Baked", default=0, min=0,
                              description="Frames of the last bake available in the cache")
    velocity_everywhere: BoolProperty(
        name="Velocity Everywhere", default=False,
        description="Store the velocity in every cell of each frame, not only where there is "
                    "smoke: for a domain used as a flame Wind Domain (larger files)")
    # --- Toon smoke ([Cartoon Smoke], plume.toon_build) ---
    toon: PointerProperty(type=PlumeToonSettings, name="Toon Smoke")
    # --- Flow-graph fire ([Graph Fire Synthesis], plume.flowgraph_build / fire_synthesize) ---
    flowgraph: PointerProperty(type=PlumeFlowGraphSettings, name="Flow-Graph Fire")

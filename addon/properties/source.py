"""A Source's and an Obstacle's properties (``obj.plume.source``, ``obj.plume.obstacle``)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty, IntProperty
from bpy.props import PointerProperty

from ..ranges import text

#: Breakup of a new Source: uneven puffs, so streak sheets and smoke fold from the start.
SMOKE_BREAKUP = 0.5


class PlumeSourceSettings(bpy.types.PropertyGroup):
    density: FloatProperty(name="Density", default=1.0, soft_min=0.0, soft_max=10.0,
                           description="ρ set in the source's cells each step")
    temperature: FloatProperty(name="Temperature", default=1.0, soft_min=-10.0, soft_max=10.0,
                               description="T - T_amb set in the source's cells each step")
    fuel: FloatProperty(name="Fuel", default=0.0, soft_min=0.0, soft_max=10.0,
                        description="F set in the source's cells (combustion domains only)")
    fuel_noise: FloatProperty(
        name="Flicker", default=0.8, min=0.0, max=1.0, subtype='FACTOR',
        description="Thins the fuel in drifting patches, so the fire leaves the source as "
                    "separate, flickering tongues instead of one even sheet (0: even fuel; 1: "
                    "the patches take all of it)")
    fuel_noise_scale: FloatProperty(
        name="Flicker Size", default=0.08, min=1e-4, soft_min=0.005, soft_max=1.0, unit='LENGTH',
        description="Size of the flicker's patches: about the width of one tongue of flame")
    fuel_noise_rate: FloatProperty(
        name="Flicker Speed", default=3.0, min=0.0, soft_max=20.0,
        description="How many times a second the flicker's patches change")
    smoke_noise: FloatProperty(
        name="Breakup", default=SMOKE_BREAKUP, min=0.0, max=1.0, subtype='FACTOR',
        description="Thins the smoke and heat the source gives off in drifting patches, so the "
                    "plume rises in uneven puffs that shear, fold and curl instead of as one "
                    "even column (0: even smoke; 1: the patches take all of it). A source that burns "
                    "fuel in a Combustion domain uses Flicker instead")
    smoke_noise_scale: FloatProperty(
        name="Breakup Size", default=0.08, min=1e-4, soft_min=0.005, soft_max=1.0, unit='LENGTH',
        description="Size of the breakup's patches: about the width of one puff")
    smoke_noise_rate: FloatProperty(
        name="Breakup Speed", default=2.0, min=0.0, soft_max=20.0,
        description="How many times a second the breakup's patches change")
    velocity: FloatVectorProperty(
        name="Initial Velocity", size=3, default=(0.0, 0.0, 0.0), subtype='VELOCITY', unit='VELOCITY',
        description="Velocity given to the air in the source's cells, m/s")
    motion_factor: FloatProperty(name="Motion Factor", default=1.0, soft_min=0.0, soft_max=2.0,
                                 description="Share of the source object's own motion added to its velocity")
    point_placement: EnumProperty(
        name="Placement", default='RIM',
        items=(('RIM', "Rim",
                "A ring of point sources around the source's outline, across the direction the "
                "smoke leaves it (its Initial Velocity, else against gravity), one a cell apart, "
                "cut into arcs of about 8 (each its own candidate group): sheets that wrap "
                "the smoke, a few per source"),
               ('CELLS', "Cells",
                "Point Sources random points in every source cell (10-20 in the Smoke Surfaces "
                "paper): the paper's set-up "
                "for a source one to four cells wide; a wide source fills the smoke's volume "
                "with streaklines and its sheets fold many times over")),
        description="Where this source's point sources are, when it has no Point Source Mesh")
    point_sources: IntProperty(
        name="Point Sources", default=16, soft_min=1, soft_max=64,
        description="Tracer point sources per source cell when Placement is Cells (10-20 in the "
                    "Smoke Surfaces paper)")
    candidate_group: IntProperty(
        name="Candidate Group", default=-1, soft_min=-1, soft_max=64,
        description="Streaklines are clustered only inside a candidate group (-1: the source's own group)")
    point_source_mesh: PointerProperty(
        name="Point Source Mesh", type=bpy.types.Object, poll=lambda _self, ob: ob.type == 'MESH',
        description="Mesh whose vertices (world space, evaluated at the domain's first frame) are "
                    "this source's point sources, one streakline each, instead of Point Sources "
                    "random points per cell; they must lie in the "
                    "domain. Its vertex groups, if any, are hand-made candidate groups: "
                    "streaklines of different groups never share a surface")
    emit_particles: BoolProperty(
        name="Emit Particles", default=True,
        description="Emit streakline particles from this source's point sources: keyframe it off "
                    "to leave a gap in the streaklines. Emission "
                    "pauses only on frames where no Source with point sources emits (every "
                    "streakline keeps the same particle count); while another source still emits, "
                    "this one's particles keep coming and carry the smoke's density there (zero "
                    "if its Density is keyframed to 0 too). The first particle is always emitted")
    candidate_split: IntProperty(
        name="Split Into Groups", default=1, soft_min=1, soft_max=64,
        description="Splits this source's point sources into this many candidate groups so that "
                    "streaklines of different parts never share a surface: a Rim into this "
                    "many arcs (1: arcs of about 8 point sources), other point sources into "
                    "groups of equal count along their longest extent (1: no split); more than "
                    "1 replaces Candidate Group; validated at bake time to "
                    f"{text('candidate_split')}")


class PlumeObstacleSettings(bpy.types.PropertyGroup):
    slip: EnumProperty(
        name="Slip", default='NO_SLIP',
        description="How the air moves along the obstacle's surface",
        items=(('NO_SLIP', "No Slip", "The air next to the obstacle moves with it"),
               ('FREE_SLIP', "Free Slip", "Only the normal part of the flow is stopped")))

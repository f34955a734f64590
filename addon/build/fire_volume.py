"""The synthesized fire (flow-graph fire, §5.3) as a Volume object over fire/fire_####.vdb with
the fire material (colour ramp of temperature, emission from flame): renders without the add-on."""

import bpy

from . import datablocks, volume
from .. import flowgraph
from ..snapshot import blend_relative


def fire_object_name(domain):
    return f"{domain.name}_fire"


def build_fire_volume(domain, folder, frame_start, frames, max_temperature):
    """Creates or updates "<domain>_fire" playing the synthesized frames. Returns the object."""
    ob = datablocks.typed_object(bpy.context.scene, fire_object_name(domain), 'VOLUME',
                                 bpy.data.volumes.new, domain.users_collection)
    volume.play_sequence(ob, blend_relative(flowgraph.fire_path(folder, frame_start)),
                         frame_start, frames, volume.material(True, max_temperature))
    domain.plume.domain.flowgraph.fire_object = ob.name
    return ob

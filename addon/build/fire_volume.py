"""The synthesized fire (flow-graph fire, §5.3) as a Volume object over fire/fire_####.vdb with
the fire material (blackbody from temperature, emission from flame): renders without the add-on."""

import bpy

from . import volume
from .. import flowgraph


def fire_object_name(domain):
    return f"{domain.name}_fire"


def build_fire_volume(domain, folder, frame_start, frames, max_temperature):
    """Creates or updates "<domain>_fire" playing the synthesized frames. Returns the object."""
    name = fire_object_name(domain)
    ob = bpy.data.objects.get(name)
    if ob is not None and ob.type != 'VOLUME':
        bpy.data.objects.remove(ob, do_unlink=True)
        ob = None
    if ob is None:
        ob = bpy.data.objects.new(name, bpy.data.volumes.new(name))
        for coll in domain.users_collection:
            coll.objects.link(ob)
        if not ob.users_collection:
            bpy.context.scene.collection.objects.link(ob)
    volume.play_sequence(ob, volume._file_path(flowgraph.fire_path(folder, frame_start)),
                         frame_start, frames, volume.material(True, max_temperature))
    domain.plume.domain.flowgraph.fire_object = ob.name
    return ob

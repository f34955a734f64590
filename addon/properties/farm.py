"""Scene › Plume Farm (``scene.plume_farm``): the Slurm cluster, the shared folder and its path
on the farm, and what to submit."""

import bpy
from bpy.props import EnumProperty, IntProperty, PointerProperty, StringProperty

JOB_ITEMS = (
    ('FLOWGRAPH', "Flow-Graph Fire",
     "The flow-graph fire end to end: the states' bakes side by side, Build Flow Graph, "
     "Synthesize Fire, then the render in chunks of frames", 'FORCE_FORCE', 0),
    ('WEDGE', "Wedge",
     "Variants of one domain (its Wedge Settings), each baked into its own cache folder and "
     "rendered as a still, then a contact sheet of the stills", 'GRID', 1),
    ('FLAMES', "Flames",
     "Bake Flames of every Flame Source, then the render in chunks of frames", 'LIGHT_SUN', 2),
    ('RENDER', "Render",
     "The scene's frame range rendered in chunks of frames (caches as they are)", 'RENDER_ANIMATION', 3),
)


def _is_domain(_self, ob):
    return getattr(ob, "plume", None) is not None and ob.plume.role == 'DOMAIN'


class PlumeFarmSettings(bpy.types.PropertyGroup):
    job: EnumProperty(name="Submit", items=JOB_ITEMS, default='FLOWGRAPH',
                      description="What the farm computes")
    folder: StringProperty(
        name="Farm Folder", subtype='DIR_PATH', default="",
        description="A folder on storage every farm machine sees: the shot's copy, the caches, "
                    "the logs and the renders go there, each job in a folder of its own")
    path_here: StringProperty(
        name="Path Here", subtype='DIR_PATH', default="",
        description="Where this machine sees the shared storage (for example ~/projects/); "
                    "empty when the farm sees the same paths")
    path_farm: StringProperty(
        name="Path on Farm", default="",
        description="Where the farm machines see that same storage (for example "
                    "/mnt/projects/)")
    partition: StringProperty(name="Partition", default="",
                              description="The Slurm partition (queue); empty for the "
                                          "cluster's default")
    account: StringProperty(name="Account", default="",
                            description="The Slurm account to charge; empty for yours")
    time_limit: IntProperty(name="Time Limit (min)", default=60, min=1, soft_max=24 * 60,
                            description="Minutes each task may run before Slurm stops it")
    cpus: IntProperty(name="CPUs per Task", default=2, min=1, soft_max=64,
                      description="Processor cores each task asks for")
    chunk: IntProperty(name="Frames per Task", default=10, min=1, soft_max=1000,
                       description="Frames one render task renders, and one task of a "
                                   "flow-graph fire's synthesis writes")
    flowgraph_domain: PointerProperty(
        type=bpy.types.Object, poll=_is_domain, name="Graph Domain",
        description="The domain whose flow graph and synthesized fire the farm makes; every "
                    "domain recording pathlines is one of its states")
    wedge_domain: PointerProperty(type=bpy.types.Object, poll=_is_domain, name="Domain",
                                  description="The domain the wedge varies")
    wedge_settings: StringProperty(
        name="Wedge Settings", default="vorticity = 0.1, 0.3, 0.6",
        description="One line of 'setting = values' separated by ';', each with the same "
                    "number of values: variant i takes the i-th value of each (the setting's "
                    "name as its tooltip's Python line shows it, e.g. vorticity, seed)")
    last_job: StringProperty(name="Last Job", subtype='DIR_PATH', default="",
                             description="The folder of the last job submitted from this scene")
    wedge_frame: IntProperty(name="Still Frame", default=40, min=0,
                             description="The frame each variant renders for the contact sheet")

"""Plume on a farm (no ``bpy`` here): a job graph of tasks (graph.py), submitted to Slurm as job
arrays with afterok dependencies (slurm.py), each task leaving a marker when it succeeds or fails
(task_wrapper in slurm.py), its state read back without blocking (status.py), and the command
line for TDs (``python -m plume.farm``, cli.py); the same graph as an Open Job Description job
template for runners without Slurm (openjd.py). What the tasks are comes from the scene
(the Blender side: farm_scene.py)."""

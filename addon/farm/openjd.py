"""A farm job graph as an Open Job Description job template (specification
`jobtemplate-2023-09`, the job format of AWS Deadline Cloud), so that a job folder runs without
Slurm: on Deadline Cloud, or locally with the `openjd` command of the openjd-cli package
(`openjd run job.openjd.json -p FarmFolder=<job folder> --step <last task> --run-dependencies`).

One step per task, named as the task; its `dependencies` are the task's `after`; a task run
`count` > 1 times gets an INT task parameter `Index` ranging over 0..count-1 (one OpenJD task
per Slurm array index). Each task runs the same `scripts/<task>.sh` as on Slurm, in the job
folder, with PLUME_TASK_INDEX set: the same command, markers (`state/`) and logs. The job folder
is the job parameter `FarmFolder` (type PATH, a directory read and written), never written into
the template, so a copy of the folder at another path, or a farm that sees the storage
elsewhere (OpenJD path mapping), runs as well. Written as JSON, which OpenJD reads as it reads
YAML (Blender's Python has no YAML module). No ``bpy`` here."""

import json
import os

from ..files import atomic

TEMPLATE_NAME = "job.openjd.json"
SPECIFICATION = "jobtemplate-2023-09"
FOLDER_PARAM = "FarmFolder"
INDEX_PARAM = "Index"

#: What a step runs: `bash -c SCRIPT plume-farm <folder> <index> <task>`. The values are bash's
#: positional arguments, never spliced into the script's text, so any folder path works. The
#: output goes to the runner's log and, as on Slurm, to logs/<task>.<index>.log (the panel and
#: `python -m plume.farm status` show a failed task's last lines from there). A Slurm array
#: index inherited from a surrounding Slurm job would win over PLUME_TASK_INDEX in the task's
#: script: it is unset first.
_RUN = ('cd "$1" || exit 1; unset SLURM_ARRAY_TASK_ID; export PLUME_TASK_INDEX="$2"; '
        'mkdir -p logs; bash "scripts/$3.sh" 2>&1 | tee -a "logs/$3.$2.log"; '
        'exit "${PIPESTATUS[0]}"')


def _step(task, timeout_s):
    index = "{{Task.Param.%s}}" % INDEX_PARAM if task.count > 1 else "0"
    action = {"command": "bash",
              "args": ["-c", _RUN, "plume-farm", "{{Param.%s}}" % FOLDER_PARAM, index,
                       task.name]}
    if timeout_s:
        action["timeout"] = int(timeout_s)
    step = {"name": task.name, "description": task.label or task.name,
            "script": {"actions": {"onRun": action}}}
    if task.count > 1:
        step["parameterSpace"] = {"taskParameterDefinitions": [
            {"name": INDEX_PARAM, "type": "INT", "range": f"0-{task.count - 1}"}]}
    if task.cpus > 1:
        step["hostRequirements"] = {"amounts": [{"name": "amount.worker.vcpu",
                                                 "min": int(task.cpus)}]}
    if task.after:
        step["dependencies"] = [{"dependsOn": name} for name in task.after]
    return step


def job_name(root):
    """The job's name: its folder's ("shot_wedge_001"), without what OpenJD would read as a
    format string."""
    name = os.path.basename(os.path.normpath(os.path.abspath(root)))
    return (name.replace("{", "(").replace("}", ")") or "plume_farm_job")[:128]


def template(graph, name, timeout_s=None):
    """The job template of `graph` (graph.FarmGraph) as a dict; `timeout_s`, each task's time
    limit (the cluster's Time Limit), or None for none."""
    graph.validate()
    return {
        "specificationVersion": SPECIFICATION,
        "name": name,
        "description": "A Plume farm job: the tasks of its graph.json, each running "
                       "scripts/<task>.sh in the job folder (made by plume.farm.openjd).",
        "parameterDefinitions": [{
            "name": FOLDER_PARAM,
            "type": "PATH",
            "objectType": "DIRECTORY",
            "dataFlow": "INOUT",
            "description": "The job folder (the one holding shot.blend, graph.json and "
                           "scripts/), as the machines that run the tasks see it.",
            "userInterface": {"control": "CHOOSE_DIRECTORY", "label": "Job Folder"},
            # Relative: OpenJD resolves it against the template's own folder, the job folder
            # wherever it is (a copy, another machine); -p FarmFolder=... says otherwise.
            "default": ".",
        }],
        "steps": [_step(t, timeout_s) for t in graph.tasks],
    }


def write(graph, root, timeout_s=None):
    """Writes `root`/job.openjd.json for `graph`; returns its path. The task scripts it runs
    (scripts/<task>.sh) are slurm.write_scripts()'s."""
    path = os.path.join(root, TEMPLATE_NAME)
    text = json.dumps(template(graph, job_name(root), timeout_s), indent=1)
    atomic.write_bytes(path, text.encode("utf-8"))
    return path

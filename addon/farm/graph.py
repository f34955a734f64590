"""A farm job graph: named tasks, each one command run `count` times (a Slurm job array: index
0..count-1 in $PLUME_TASK_INDEX), after the tasks it depends on have all succeeded. Plain data,
saved as `graph.json` in the farm folder so that a resubmission runs the same graph."""

import json
import os
from dataclasses import asdict, dataclass, field
from typing import List

from ..files import atomic

GRAPH_NAME = "graph.json"
FORMAT = 1


class FarmError(Exception):
    """A graph or a cluster setting that cannot be submitted; the message is the artist's."""


@dataclass
class Task:
    name: str                    # letters, digits, _ and -: file and job names are made from it
    argv: List[str]              # the command; "{index}" in an argument becomes the index
    count: int = 1               # array size: indices 0 .. count-1
    after: List[str] = field(default_factory=list)  # tasks that must all succeed first
    cpus: int = 1                # CPUs per task
    label: str = ""              # what the panel shows ("bake state 'Fire_A'")


@dataclass
class FarmGraph:
    tasks: List[Task]

    def task(self, name):
        return next(t for t in self.tasks if t.name == name)

    def validate(self):
        """FarmError unless names are unique and plain, dependencies exist and come first."""
        seen = set()
        for t in self.tasks:
            if not t.name or not all(c.isalnum() or c in "_-" for c in t.name):
                raise FarmError(f"Plume farm: task name '{t.name}' must be letters, digits, _ or -")
            if t.name in seen:
                raise FarmError(f"Plume farm: two tasks are named '{t.name}'")
            missing = [a for a in t.after if a not in seen]
            if missing:
                raise FarmError(f"Plume farm: task '{t.name}' runs after {missing}, which are "
                                "not earlier tasks of the graph")
            if t.count < 1 or t.cpus < 1 or not t.argv:
                raise FarmError(f"Plume farm: task '{t.name}' needs a command, count ≥ 1 and "
                                "CPUs ≥ 1")
            seen.add(t.name)
        return self


def save(graph, root):
    graph.validate()
    text = json.dumps({"format": FORMAT, "tasks": [asdict(t) for t in graph.tasks]}, indent=1)
    atomic.write_bytes(os.path.join(root, GRAPH_NAME), text.encode("utf-8"))


def load(root):
    path = os.path.join(root, GRAPH_NAME)
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        raise FarmError(f"Plume farm: no readable job graph in {root} ({e})") from None
    if data.get("format") != FORMAT:
        raise FarmError(f"Plume farm: {path} is format {data.get('format')}, this Plume reads "
                        f"{FORMAT}")
    return FarmGraph([Task(**t) for t in data["tasks"]]).validate()

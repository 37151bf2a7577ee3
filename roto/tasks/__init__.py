"""Task registry: name -> task object."""

from __future__ import annotations

from roto.tasks.baoding import Baoding
from roto.tasks.base import Task
from roto.tasks.bounce import Bounce

TASKS: dict[str, Task] = {"bounce": Bounce(), "baoding": Baoding()}


def get_task(name: str) -> Task:
    """The task called ``name`` (case-insensitive); a clear error lists the valid names."""
    key = str(name).lower()
    if key not in TASKS:
        raise ValueError(f"unknown task {name!r}; valid tasks: {sorted(TASKS)}")
    return TASKS[key]

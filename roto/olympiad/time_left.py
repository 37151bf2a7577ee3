"""How long a plan's unfinished cells will take: each cell's env steps left at its task's throughput.

Pure functions over plain numbers, so that ``roto olympiad --dry-run`` can state its estimate and
the tests can check it without a study or a run directory.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping


def busiest_worker_load(loads: Iterable[float], workers: int) -> float:
    """The load of the busiest of ``workers`` workers when the cells' loads (env steps or seconds)
    go, largest first, each to the least loaded worker (a cell is never split between workers)."""
    totals = [0.0] * workers
    for load in sorted(loads, reverse=True):
        totals[totals.index(min(totals))] += load
    return max(totals)


def recent_rate(records: list[dict]) -> float | None:
    """Training env steps per second between a run's last two evaluations (None without two)."""
    if len(records) < 2 or "train_wall_s" not in records[-1] or "train_wall_s" not in records[-2]:
        return None
    seconds = records[-1]["train_wall_s"] - records[-2]["train_wall_s"]
    return (records[-1]["env_steps"] - records[-2]["env_steps"]) / seconds if seconds > 0 else None


def throughput(summaries: Iterable[Mapping]) -> float:
    """Finished cells' training env steps per second: all their env steps over all their training
    seconds (``env_steps`` and ``train_wall_s`` of each summary); 0 without any."""
    summaries = list(summaries)
    seconds = sum(summary["train_wall_s"] for summary in summaries)
    return sum(summary["env_steps"] for summary in summaries) / seconds if seconds > 0 else 0.0


def task_throughputs(summaries: Iterable[Mapping]) -> dict[str, float]:
    """Per task, the ``throughput`` of its finished cells' summaries (tasks without any left out)."""
    by_task: dict[str, list[Mapping]] = {}
    for summary in summaries:
        by_task.setdefault(summary["task"], []).append(summary)
    rates = {task: throughput(group) for task, group in by_task.items()}
    return {task: rate for task, rate in rates.items() if rate > 0}


def cell_seconds(
    steps_left: Mapping[str, int], task_of: Mapping[str, str], rates: Mapping[str, float], fallback: float
) -> dict[str, float]:
    """Seconds each cell has left: its env steps left at its task's rate (``rates``, env steps/s),
    or at ``fallback`` for a task without one. ``steps_left`` and ``task_of`` are keyed by cell."""
    return {name: steps / rates.get(task_of[name], fallback) for name, steps in steps_left.items()}


def rate_sources(rates: Mapping[str, float], tasks: Iterable[str], fallback: float, fallback_source: str) -> str:
    """``bounce 2804, baoding 2088 env steps/s (...)``: the rate each task of the unfinished cells
    is estimated at, and where the rates come from."""
    named = list(dict.fromkeys(tasks))  # each task once, in order
    per_task = ", ".join(f"{task} {rates.get(task, fallback):.0f}" for task in named)
    missing = [task for task in named if task not in rates]
    tail = f"; {', '.join(missing)} at {fallback_source}" if missing and rates else ""
    source = "the finished cells' throughput per task" if rates else fallback_source
    return f"{per_task} env steps/s ({source}{tail})"

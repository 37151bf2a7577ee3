"""Baoding's measures of the balls' paths in ``roto results``: the round rotations its pages lead
with (``Task.selection_metric``), the path metrics beside the headline metric, and the measures a
summary written before they existed gets from its stored episodes."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable

import numpy as np

from roto.olympiad.results import Agents, Key, markdown_table, metric, scores_by_cell
from roto.tasks import get_task


def with_derived_means(task: str, evaluation: dict) -> dict:
    """``evaluation`` (a summary's ``final`` or ``best``) with the ``<name>_mean`` of each of the
    task's ``derived_metrics`` it lacks but can recompute from its stored episodes (``per_episode``:
    {measure: one value per episode}); a summary written before such a measure existed gets it so."""
    episodes = evaluation.get("per_episode") or {}
    count = min((len(values) for values in episodes.values()), default=0)
    derived = [get_task(task).derived_metrics({k: v[i] for k, v in episodes.items()}) for i in range(count)]
    if not derived or not derived[0]:
        return evaluation
    means = {f"{name}_mean": float(np.mean([d[name] for d in derived])) for name in derived[0]}
    return {**means, **evaluation}


def path_metric_table(summaries: list[dict]) -> list[str]:
    """Markdown lines: each seed's ``best.pt`` headline metric beside its path metrics
    (``Task.path_metrics``, e.g. Baoding's net turns), a table per task that has them; empty if none
    does. A measure that follows from the stored episodes (``Task.derived_metrics``) is recomputed
    where a summary lacks it; summaries written before evaluations measured paths say "not measured"."""
    lines = []
    for task in sorted({s["task"] for s in summaries}):
        names = get_task(task).path_metric_names
        if not names:
            continue
        header = ["cell", f"{metric(task)} (best.pt)", *names]
        lines += [
            f"## best policy, {task}: path metrics beside the headline metric, per seed",
            "",
            "| " + " | ".join(header) + " |",
            "|" + "---|" * len(header),
        ]
        for s in sorted(summaries, key=lambda s: (s["robot"], s["obs"], s["variant"], s["seed"])):
            if s["task"] == task:
                best = with_derived_means(task, s["best"])
                values = [f"{best[f'{n}_mean']:.2f}" if f"{n}_mean" in best else "not measured" for n in names]
                cell = f"{s['robot']} / {s['obs']} / {s['variant']} / seed {s['seed']}"
                lines.append("| " + " | ".join([cell, f"{best[f'{metric(task)}_mean']:.2f}", *values]) + " |")
        lines.append("")
    return lines


def seed_measures(
    summaries: Iterable[dict], task: str, measure: str, policy: str = "best"
) -> dict[tuple[str, str, str], dict[int, float | None]]:
    """{(robot, obs, variant): {seed: ``measure`` of that seed's ``policy`` ("final" or "best") on
    ``task``, None where its summary neither holds nor can recompute it (``with_derived_means``)}}."""
    found: dict[tuple[str, str, str], dict[int, float | None]] = {}
    for s in summaries:
        if s["task"] == task:
            value = with_derived_means(task, s[policy]).get(f"{measure}_mean")
            found.setdefault((s["robot"], s["obs"], s["variant"]), {})[s["seed"]] = value
    return found


def measure_scores(
    summaries: Iterable[dict], task: str, measure: str, policy: str = "best"
) -> dict[tuple[str, str, str], np.ndarray | None]:
    """{(robot, obs, variant): (seeds,) ``measure`` of each seed's ``policy`` ("final" or "best") on
    ``task``, seeds in order; None where some seed's summary neither holds nor can recompute it
    (``seed_measures``)."""
    return {
        row: None if None in seeds.values() else np.array([seeds[seed] for seed in sorted(seeds)])
        for row, seeds in seed_measures(summaries, task, measure, policy).items()
    }


def seed_path_kind(task: str, summary: dict, policy: str = "best") -> str | None:
    """What one seed's ``policy`` did with the balls (``Task.path_kind`` of its evaluation's means:
    Baoding "round", "swing" or "no swaps"); None for a task without kinds or a summary that
    cannot tell."""
    means = with_derived_means(task, summary[policy])
    return get_task(task).path_kind({k.removesuffix("_mean"): v for k, v in means.items() if k.endswith("_mean")})


def kind_counts(kinds: Iterable[str | None]) -> str:
    """The seeds' kinds counted, most frequent first ("round 4, swing 1"); "" when none has a kind,
    "not measured" standing for a seed without one beside seeds with."""
    names = ["not measured" if kind is None else kind for kind in kinds]
    if all(name == "not measured" for name in names):
        return ""
    counts = Counter(names)
    return ", ".join(f"{name} {n}" for name, n in sorted(counts.items(), key=lambda item: (-item[1], item[0])))


def lead_scores(summaries: list[dict], policy: str = "best") -> tuple[dict[Key, np.ndarray], list[Key]]:
    """The cells of tasks that lead with another measure than their headline metric
    (``Task.selection_metric``: Baoding's round rotations): ({cell: (seeds,) scores of that measure},
    [cells whose summaries, some seed's at least, did not measure it, nor can it be recomputed])."""
    found: dict[Key, np.ndarray | None] = {}
    for task in sorted({s["task"] for s in summaries}):
        lead = get_task(task).selection_metric
        if lead is not None:
            found.update({(task, *row): v for row, v in measure_scores(summaries, task, lead, policy).items()})
    scores = {key: v for key, v in sorted(found.items()) if v is not None}
    return scores, sorted(key for key, v in found.items() if v is None)


def lead_measure_scores(summaries: list[dict]) -> dict[Key, np.ndarray]:
    """{cell: (seeds,) the best policies' lead measure}: Baoding's round rotations
    (``lead_scores``; a cell whose summaries cannot tell them is left out), every other task's
    headline metric. What the probabilities of improvement compare."""
    headline = {key: v for key, v in scores_by_cell(summaries, "best").items() if not get_task(key[0]).selection_metric}
    return {**headline, **lead_scores(summaries, "best")[0]}


def lead_section(summaries: list[dict], agents: Agents, current: set[str]) -> list[str]:
    """Markdown lines leading the results where a task leads with another measure than its headline
    metric: the best policies' round rotations (Baoding), before roto's swap count; empty if none.
    ``current``: the tasks whose summaries are all of the task's current version."""
    scores, unmeasured = lead_scores(summaries, "best")
    if not scores and not unmeasured:
        return []
    tasks = sorted({key[0] for key in (*scores, *unmeasured)})
    names = ", ".join(f"{t}: {get_task(t).selection_metric} (roto's {metric(t)} in the tables below)" for t in tasks)
    lines = [f"## best policy: {names}, per 10 s episode, mean ± std over seeds", ""]
    if scores:
        lines += [markdown_table(scores, agents, current, references=False), ""]
    if unmeasured:
        cells = ", ".join(" / ".join(key) for key in unmeasured)
        lines += [f"Not measured (summaries written before evaluations followed the balls' paths): {cells}.", ""]
    return lines

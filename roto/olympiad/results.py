"""``roto results``: the Olympiad's tables and learning curves from its cells' summaries.

Per cell (task, robot, obs mode, variant) the score of a run (seed) is its policy's task metric
(bounces or rotations per 10 s episode) averaged over the plan's evaluation episodes; the table
gives the mean ± std over seeds and the interquartile mean with a 95 % stratified bootstrap
interval (``roto.olympiad.stats``), for the final and for the best policy. Hands are rows, task ×
obs mode × variant are columns, each named with the agent config it trained, with each task's
reference of each hand (``Task.reference``) and roto v1's Shadow figures (docs/spec.md §9) beside the
variants that declare themselves roto's agent. Baoding's pages lead with round rotations
(``roto.olympiad.path_results``); the page itself is ``roto.olympiad.results_page``.
"""

from __future__ import annotations

import contextlib
import csv
import pathlib
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from roto.artifact_formats import FORMAT_KEY, check_format
from roto.eval.plots import plot_variants
from roto.olympiad.plan import load_plan
from roto.olympiad.stats import iqm, probability_of_improvement, stratified_bootstrap_ci
from roto.result_files import read_json, replacing
from roto.robots import ROBOTS
from roto.tasks import get_task
from roto.tasks.base import lead_metric

ROTO_V1_SHADOW = {
    ("bounce", "blind", "ppo"): 69.0,
    ("bounce", "proprio", "ppo"): 53.0,
    ("bounce", "blind", "forward_dynamics"): 79.0,
    ("bounce", "blind", "forward_dynamics_memory"): 75.0,
    ("baoding", "blind", "ppo"): 5.1,
    ("baoding", "proprio", "ppo"): 0.1,
    ("baoding", "blind", "forward_dynamics"): 9.9,
    ("baoding", "blind", "forward_dynamics_memory"): 17.4,
}
"""roto v1 on the Shadow hand after 200 M steps, mean of 5 seeds, by (task, obs mode, roto's agent)
(docs/spec.md §9): set only beside a variant that declares itself that agent (``roto_agent``)."""

Key = tuple[str, str, str, str]  # task, robot, obs, variant
Agents = dict[tuple[str, str], dict[str, Any]]
"""{(task, variant): {"label": the agent config and overrides, "roto_agent": roto's agent or None}}."""


def metric(task: str) -> str:
    """The task's headline metric (``Task.headline_metric``)."""
    return get_task(task).headline_metric


def lead_measure(task: str) -> str:
    """The measure a task's results lead with: its selection metric, else its headline metric."""
    return lead_metric(get_task(task))


LABEL_COMMITS = 3
"""A page label names at most this many commits; beyond, it counts them (manifest.csv names each cell's)."""


def page_label(summaries: list[dict], plan: str = "") -> str:
    """ "plan <name>, commit <c1>, <c2>" of a folder of summaries: the commits that wrote them and
    those that trained them, or "plan <name>, <n> commits, each cell's in manifest.csv" beyond
    ``LABEL_COMMITS`` (``plan``: a name or file that wins over the plan the summaries record)."""
    commits = sorted({c for s in summaries for c in (s["commit"], *(t["commit"] for t in s.get("trained_by", [])))})
    if len(commits) <= LABEL_COMMITS:
        return f"plan {plan or summaries[0]['plan']}, commit {', '.join(commits)}"
    return f"plan {plan or summaries[0]['plan']}, {len(commits)} commits, each cell's in manifest.csv"


def variant_agents(summaries: list[dict], plan: str = "") -> Agents:
    """What each (task, variant) trained: from the plan when ``plan`` names a packaged plan or a
    file, else from the summaries (which record it), else only the variant's name."""
    agents: Agents = {}
    for s in summaries:
        agents.setdefault((s["task"], s["variant"]), s.get("agent") or {"label": "", "roto_agent": None})
    with contextlib.suppress(ValueError, FileNotFoundError):
        for name, variant in load_plan(plan).variants.items() if plan else ():
            for entry in variant.per_task:
                agents[(entry.task, name)] = {"label": entry.label, "roto_agent": entry.roto_agent}
    return agents


def read_summaries(folder: str | pathlib.Path) -> list[dict]:
    """Every cell summary (``<cell>.json``) in ``folder``, each checked (``check_summary``)."""
    folder = pathlib.Path(folder)
    if not folder.is_dir():
        what = "is a file" if folder.exists() else "does not exist"
        raise FileNotFoundError(
            f"the folder of cell summaries {str(folder)!r} {what}; give the folder a plan's --results wrote"
        )
    paths = sorted(folder.glob("*-seed*.json"))
    if not paths:
        raise FileNotFoundError(f"no cell summaries (<task>-<robot>-<obs>-<variant>-seed<k>.json) in {str(folder)!r}")
    return [check_summary(path, read_json(path, "cell summary")) for path in paths]


SUMMARY_FIELDS = {
    "task": str,
    "robot": str,
    "obs": str,
    "variant": str,
    "seed": int,
    "plan": str,
    "commit": str,
    "evaluations": list,
    "final": dict,
    "best": dict,
}
"""The fields ``roto results`` reads from every cell summary, with their JSON types."""
JSON_TYPES = {str: "a string", int: "an integer", list: "an array", dict: "an object"}
RECORD_FIELDS = ("env_steps", "train_wall_s")
"""The numbers every evaluation record of a summary holds besides its task metric's mean."""


def json_kind(value: Any) -> str:
    """What a JSON value is, in JSON's words: an object, an array of 3 items, a string ('x'), null, ..."""
    if isinstance(value, list):
        return f"an array of {len(value)} items"
    kinds = ((dict, "an object"), (str, "a string"), (bool, "a boolean"), (int, "an integer"), (float, "a number"))
    return next((f"{name} ({value!r:.40})" for kind, name in kinds if isinstance(value, kind)), "null")


def require_fields(where: str, data: dict, fields: dict[str, type], expected: str = "it needs") -> None:
    """Refuse ``data`` (the JSON object ``where`` names) lacking one of ``fields`` ({name: its
    Python type: str, int, list or dict}) or holding one of another type (a boolean is no integer);
    the message names the field, what was expected and what was found."""
    missing = [key for key in fields if key not in data]
    if missing:
        raise ValueError(f"{where} lacks the field(s) {missing}; {expected} {list(fields)}")
    for key, kind in fields.items():
        if not isinstance(data[key], kind) or isinstance(data[key], bool):
            raise ValueError(f"{where}: {key!r} should be {JSON_TYPES[kind]}, found {json_kind(data[key])}")


def check_summary(path: str | pathlib.Path, summary: Any) -> dict:
    """``summary``, read from ``path``, if it has what ``roto results`` reads (``SUMMARY_FIELDS``, and
    the task metric's mean in its final, best and evaluation records); else a ValueError naming the
    file, what was expected and what was found."""
    where = f"cell summary {str(path)!r}"
    if not isinstance(summary, dict):
        raise ValueError(f"{where} holds {json_kind(summary)}, not an object (a cell summary of roto olympiad)")
    check_format("cell summary", summary.get(FORMAT_KEY), where)
    require_fields(where, summary, SUMMARY_FIELDS, "a cell summary has")
    try:
        mean = f"{metric(summary['task'])}_mean"
    except ValueError as error:  # an unknown task, named with the valid ones
        raise ValueError(f"{where}: {error}") from None
    records = [("final", summary["final"], (mean,)), ("best", summary["best"], (mean,))]
    records += [(f"evaluations[{i}]", r, (*RECORD_FIELDS, mean)) for i, r in enumerate(summary["evaluations"])]
    for part, record, keys in records:
        if not isinstance(record, dict):
            raise ValueError(f"{where}: {part} should be an object, found {json_kind(record)}")
        for key in keys:
            if isinstance(record.get(key), bool) or not isinstance(record.get(key), (int, float)):
                found = json_kind(record[key]) if key in record else "no such field"
                raise ValueError(f"{where}: {part} should hold the number {key!r}, found {found}")
    return summary


def scores_by_cell(summaries: Iterable[dict], policy: str = "final") -> dict[Key, np.ndarray]:
    """{(task, robot, obs, variant): (seeds,) scores of ``policy`` ("final" or "best")}."""
    found: dict[Key, list[tuple[int, float]]] = {}
    for s in summaries:
        key = (s["task"], s["robot"], s["obs"], s["variant"])
        found.setdefault(key, []).append((s["seed"], s[policy][f"{metric(s['task'])}_mean"]))
    return {key: np.array([score for _, score in sorted(runs)]) for key, runs in sorted(found.items())}


def cell_statistics(scores: np.ndarray, seed: int = 0) -> dict[str, float]:
    """Mean, std (population), IQM and its 95 % stratified bootstrap interval of one cell's seeds."""
    low, high = stratified_bootstrap_ci(scores[:, None], seed=seed)
    return {
        "n": int(scores.size),
        "mean": float(scores.mean()),
        "std": float(scores.std()),
        "iqm": iqm(scores),
        "iqm_low": low,
        "iqm_high": high,
    }


def improvements(scores: dict[Key, np.ndarray]) -> list[tuple[str, str, str, str, str, float]]:
    """(task, robot, obs, variant x, variant y, P(x > y)) for every pair of variants of a setting
    that both have at least two seeds (one run against one run is a comparison, not a probability)."""
    out = []
    for (task, robot, obs, x), sx in scores.items():
        for (task_y, robot_y, obs_y, y), sy in scores.items():
            if (task, robot, obs) == (task_y, robot_y, obs_y) and x < y and min(sx.size, sy.size) >= 2:
                out.append((task, robot, obs, x, y, probability_of_improvement(sx[:, None], sy[:, None])))
    return out


def current_tasks(summaries: list[dict]) -> set[str]:
    """Tasks whose every summary records the task's current version (``Task.version``)."""
    tasks = {s["task"] for s in summaries}
    return {t for t in tasks if all(s.get("task_version") == get_task(t).version for s in summaries if s["task"] == t)}


def markdown_table(
    scores: dict[Key, np.ndarray],
    agents: Agents | None = None,
    current: set[str] | None = None,
    references: bool = True,
) -> str:
    """Hands as rows, (task, obs, variant: its agent) as columns; each task's reference (``Task.reference``)
    and roto v1's figure beside the variants that declare themselves roto's agent (``references``:
    both are in the headline metric, so a table of another measure leaves them out)."""
    agents = agents or {}
    columns = sorted({(task, obs, variant) for task, _, obs, variant in scores})
    tasks = sorted({task for task, _, _ in columns})
    order = list(ROBOTS)  # the hand registry's order
    robots = sorted({robot for _, robot, _, _ in scores}, key=lambda r: order.index(r) if r in order else len(order))

    current = [t for t in tasks if t in (current or set())]  # tasks whose summaries are all of today's version

    def header(task: str, obs: str, variant: str) -> str:
        label = agents.get((task, variant), {}).get("label")
        version = f"v{get_task(task).version}" if task in current else "older or unrecorded version"
        return f"{task} ({version}) / {obs} / {variant}" + (f": {label}" if label else "")

    head = ["hand", *(header(*column) for column in columns)]
    tasks = current if references else []  # a reference stands only beside scores of the task it was measured on
    head += [f"{get_task(t).reference_name} ({metric(t)}, v{get_task(t).version})" for t in tasks]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for robot in robots:
        cells = [
            _format(cell_statistics(scores[key]) if (key := (t, robot, o, v)) in scores else None)
            for t, o, v in columns
        ]
        refs = [f"{get_task(t).reference[robot]}" if robot in get_task(t).reference else "" for t in tasks]
        lines.append("| " + " | ".join([robot, *cells, *refs]) + " |")
    reference = []
    for task, obs, variant in columns:
        roto_agent = agents.get((task, variant), {}).get("roto_agent")
        figure = ROTO_V1_SHADOW.get((task, obs, roto_agent)) if roto_agent else None
        reference.append(f"{figure} ({roto_agent})" if figure is not None else "")
    if references and any(reference):  # no row of blanks where no column is roto's agent
        row = ["roto v1, Shadow, 200 M steps (5 seeds)", *reference, *[""] * len(tasks)]
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def _format(stats: dict | None) -> str:
    if stats is None:
        return ""
    if stats["n"] == 1:  # one seed: no spread, and an IQM or interval of one value says nothing more
        return f"{stats['mean']:.1f} (n=1)"
    interval = f"[{stats['iqm_low']:.1f}, {stats['iqm_high']:.1f}]"
    return f"{stats['mean']:.1f} ± {stats['std']:.1f} (IQM {stats['iqm']:.1f} {interval}, n={stats['n']})"


def write_csv(scores: dict[Key, np.ndarray], path: pathlib.Path, policy: str) -> None:
    """One row per cell: its statistics and its seeds' scores."""
    with replacing(path) as temporary, temporary.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(
            [
                "policy",
                "task",
                "robot",
                "obs",
                "variant",
                "metric",
                "n",
                "mean",
                "std",
                "iqm",
                "iqm_ci95_low",
                "iqm_ci95_high",
                "scores",
            ]
        )
        for (task, robot, obs, variant), runs in scores.items():
            s = cell_statistics(runs)
            writer.writerow(
                [
                    policy,
                    task,
                    robot,
                    obs,
                    variant,
                    metric(task),
                    s["n"],
                    s["mean"],
                    s["std"],
                    s["iqm"],
                    s["iqm_low"],
                    s["iqm_high"],
                    " ".join(f"{v:.4g}" for v in runs),
                ]
            )


Curves = dict[tuple[str, str], dict[str, list]]  # {(task, robot): {"obs / variant": [records of each seed]}}


def curves_by_pair(summaries: list[dict], records: Callable[[dict], list[dict]]) -> Curves:
    """{(task, robot): {"obs / variant": [records(summary) of each seed]}}, seeds in order; a
    summary whose ``records`` are empty is left out."""
    groups: dict[tuple[str, str], dict[str, list]] = {}
    for s in sorted(summaries, key=lambda s: (s["task"], s["robot"], s["obs"], s["variant"], s["seed"])):
        rows = records(s)
        if rows:
            groups.setdefault((s["task"], s["robot"]), {}).setdefault(f"{s['obs']} / {s['variant']}", []).append(rows)
    return groups


def action_std_records(summary: dict) -> list[dict]:
    """The policy's action std in training at each evaluation (``training``; empty in summaries
    written before they kept it), as records ``plot_variants`` reads."""
    return [
        {"env_steps": r["env_steps"], "action_std_mean": r["ppo/action_std"]}
        for r in summary.get("training", [])
        if "ppo/action_std" in r
    ]


def curve_measure(task: str, curves: dict[str, list[list[dict]]]) -> str:
    """What a (task, robot)'s curves plot: the task's lead measure (``lead_measure``: Baoding's round
    rotations) where every evaluation record of every run has its mean, else its headline metric
    (summaries written before evaluations measured the lead)."""
    return lead_metric(get_task(task), [r for seeds in curves.values() for records in seeds for r in records])


def plot_curves(summaries: list[dict], out: pathlib.Path, plan: str = "") -> list[pathlib.Path]:
    """Per (task, robot): evaluation lead measure (``curve_measure``) against env steps and training
    wall time, mean over seeds with a min-max band, one line per (obs mode, variant); and, where
    summaries keep it, the policy's action std in training against env steps
    (``action_std_<task>_<robot>.png``). Each title names ``plan`` (else the summaries' plan) and
    the commits of that plot's own runs, so a plot changes only when its runs do."""
    paths = []
    for (task, robot), curves in curves_by_pair(summaries, lambda s: s["evaluations"]).items():
        path = out / f"curves_{task}_{robot}.png"
        title = f"{task} / {robot} ({page_label(pair_summaries(summaries, task, robot), plan)})"
        plot_variants(curves, curve_measure(task, curves), path, title=title, xs=("env_steps", "train_wall_s"))
        paths.append(path)
    for (task, robot), curves in curves_by_pair(summaries, action_std_records).items():
        path = out / f"action_std_{task}_{robot}.png"
        kept = [s for s in pair_summaries(summaries, task, robot) if action_std_records(s)]
        plot_variants(
            curves,
            "action_std",
            path,
            title=f"{task} / {robot} ({page_label(kept, plan)})",
            ylabel="policy's action std in training (mean over seeds)",
        )
        paths.append(path)
    return paths


def pair_summaries(summaries: list[dict], task: str, robot: str) -> list[dict]:
    """The summaries of one (task, robot)."""
    return [s for s in summaries if s["task"] == task and s["robot"] == robot]

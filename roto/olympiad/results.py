"""``roto results``: the Olympiad's tables and learning curves from its cells' summaries.

Per cell (task, robot, obs mode, variant) the score of a run (seed) is its policy's task metric
(bounces or rotations per 10 s episode) averaged over the plan's evaluation episodes; the table
gives the mean ± std over seeds and the interquartile mean with a 95 % stratified bootstrap
interval (``roto.olympiad.stats``), for the final and for the best policy. Hands are rows, task ×
obs mode × variant are columns, with the scripted Bounce reference of each hand
(docs/robots.md) and roto v1's Shadow figures (docs/spec.md §9) beside them.
"""

from __future__ import annotations

import csv
import pathlib
from collections.abc import Iterable

import numpy as np

from roto.eval.plots import plot_variants
from roto.olympiad.stats import iqm, probability_of_improvement, stratified_bootstrap_ci
from roto.result_files import read_json, replacing, write_text_atomic

METRIC = {"bounce": "bounces", "baoding": "rotations"}
SCRIPTED_BOUNCE = {"shadow": 27.9, "shadow_lite": 9.5, "allegro": 11.8, "orca": 12.0}
"""Bounces per 10 s episode of each hand's scripted Bounce policy (docs/robots.md)."""
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
"""roto v1 on the Shadow hand after 200 M steps, mean of 5 seeds, by (task, obs mode, variant name)
(docs/spec.md §9)."""

Key = tuple[str, str, str, str]  # task, robot, obs, variant


def read_summaries(folder: str | pathlib.Path) -> list[dict]:
    """Every cell summary (``<cell>.json``) in ``folder``."""
    paths = sorted(pathlib.Path(folder).glob("*-seed*.json"))
    if not paths:
        raise FileNotFoundError(f"no cell summaries (<task>-<robot>-<obs>-<variant>-seed<k>.json) in {str(folder)!r}")
    return [read_json(path, "cell summary") for path in paths]


def scores_by_cell(summaries: Iterable[dict], policy: str = "final") -> dict[Key, np.ndarray]:
    """{(task, robot, obs, variant): (seeds,) scores of ``policy`` ("final" or "best")}."""
    found: dict[Key, list[tuple[int, float]]] = {}
    for s in summaries:
        key = (s["task"], s["robot"], s["obs"], s["variant"])
        found.setdefault(key, []).append((s["seed"], s[policy][f"{METRIC[s['task']]}_mean"]))
    return {key: np.array([score for _, score in sorted(runs)]) for key, runs in sorted(found.items())}


def cell_statistics(scores: np.ndarray, seed: int = 0) -> dict[str, float]:
    """Mean, std (population), IQM and its 95 % stratified bootstrap interval of one cell's seeds."""
    low, high = stratified_bootstrap_ci(scores[:, None], seed=seed)
    return {"n": int(scores.size), "mean": float(scores.mean()), "std": float(scores.std()), "iqm": iqm(scores),
            "iqm_low": low, "iqm_high": high}  # fmt: skip


def improvements(scores: dict[Key, np.ndarray]) -> list[tuple[str, str, str, str, str, float]]:
    """(task, robot, obs, variant x, variant y, P(x > y)) for every pair of variants of a setting."""
    out = []
    for (task, robot, obs, x), sx in scores.items():
        for (task_y, robot_y, obs_y, y), sy in scores.items():
            if (task, robot, obs) == (task_y, robot_y, obs_y) and x < y:
                out.append((task, robot, obs, x, y, probability_of_improvement(sx[:, None], sy[:, None])))
    return out


def markdown_table(scores: dict[Key, np.ndarray]) -> str:
    """Hands as rows, (task, obs, variant) as columns; scripted and roto v1 references beside."""
    columns = sorted({(task, obs, variant) for task, _, obs, variant in scores})
    robots = sorted({robot for _, robot, _, _ in scores}, key=lambda r: list(SCRIPTED_BOUNCE).index(r))
    head = ["hand", *(f"{t} / {o} / {v}" for t, o, v in columns), "scripted Bounce"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for robot in robots:
        cells = []
        for task, obs, variant in columns:
            runs = scores.get((task, robot, obs, variant))
            stats = cell_statistics(runs) if runs is not None else None
            cells.append(_format(stats))
        lines.append("| " + " | ".join([robot, *cells, f"{SCRIPTED_BOUNCE[robot]}"]) + " |")
    reference = [f"{ROTO_V1_SHADOW[column]}" if column in ROTO_V1_SHADOW else "" for column in columns]
    lines.append("| " + " | ".join(["roto v1, Shadow, 200 M steps (5 seeds)", *reference, ""]) + " |")
    return "\n".join(lines)


def _format(stats: dict | None) -> str:
    if stats is None:
        return ""
    interval = f"[{stats['iqm_low']:.1f}, {stats['iqm_high']:.1f}]"
    return f"{stats['mean']:.1f} ± {stats['std']:.1f} (IQM {stats['iqm']:.1f} {interval}, n={stats['n']})"


def write_csv(scores: dict[Key, np.ndarray], path: pathlib.Path, policy: str) -> None:
    """One row per cell: its statistics and its seeds' scores."""
    with replacing(path) as temporary, temporary.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["policy", "task", "robot", "obs", "variant", "metric", "n", "mean", "std", "iqm",
                         "iqm_ci95_low", "iqm_ci95_high", "scores"])  # fmt: skip
        for (task, robot, obs, variant), runs in scores.items():
            s = cell_statistics(runs)
            writer.writerow([policy, task, robot, obs, variant, METRIC[task], s["n"], s["mean"], s["std"], s["iqm"],
                             s["iqm_low"], s["iqm_high"], " ".join(f"{v:.4g}" for v in runs)])  # fmt: skip


def plot_curves(summaries: list[dict], out: pathlib.Path, label: str) -> list[pathlib.Path]:
    """Per (task, robot): evaluation metric against env steps and training wall time, mean over
    seeds with a min-max band, one line per (obs mode, variant)."""
    groups: dict[tuple[str, str], dict[str, list]] = {}
    for s in sorted(summaries, key=lambda s: (s["task"], s["robot"], s["obs"], s["variant"], s["seed"])):
        curves = groups.setdefault((s["task"], s["robot"]), {})
        curves.setdefault(f"{s['obs']} / {s['variant']}", []).append(s["evaluations"])
    paths = []
    for (task, robot), curves in groups.items():
        path = out / f"curves_{task}_{robot}.png"
        plot_variants(curves, METRIC[task], path, title=f"{task} / {robot} ({label})", xs=("env_steps", "train_wall_s"))
        paths.append(path)
    return paths


def write_results(source: str | pathlib.Path, out: str | pathlib.Path, plan: str = "") -> dict[str, str]:
    """results.md, results.csv and curve PNGs in ``out`` from the summaries in ``source``."""
    summaries = read_summaries(source)
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    commits = sorted({s["commit"] for s in summaries})
    label = f"plan {plan or summaries[0]['plan']}, commit {', '.join(commits)}"
    md = [f"# Olympiad results ({label})", ""]
    for policy in ("final", "best"):
        scores = scores_by_cell(summaries, policy)
        write_csv(scores, out / f"results_{policy}.csv", policy)
        heading = f"## {policy} policy: task metric per 10 s episode, mean ± std over seeds"
        md += [heading, "", markdown_table(scores), ""]
    pairs = improvements(scores_by_cell(summaries, "final"))
    if pairs:
        md += ["## Probability of improvement (final policies)", ""]
        md += [f"- {t} / {r} / {o}: P({x} > {y}) = {p:.2f}" for t, r, o, x, y, p in pairs]
    write_text_atomic(out / "results.md", "\n".join(md) + "\n")
    plots = plot_curves(summaries, out, label)
    return {"markdown": str(out / "results.md"), "plots": [str(p) for p in plots], "cells": len(summaries)}

"""Learning curves from runs' ``evaluations.jsonl`` (one line per training-time evaluation)."""

from __future__ import annotations

import pathlib
import textwrap
from collections.abc import Mapping, Sequence

import numpy as np

from roto.result_files import replacing
from roto.rl.evaluation import best_eval_key, read_evaluations


def curve_metrics(records: Sequence[Mapping]) -> list[str]:
    """The per-episode quantities a run's evaluations hold, the return first, without the length."""
    names = [key.removesuffix("_mean") for key in records[0] if key.endswith("_mean")]
    return sorted((n for n in names if n != "length"), key=lambda n: (n != "return", n))


def best_evaluation(records: Sequence[Mapping], selection_metric: str | None = None) -> int:
    """The index of the evaluation ``best.pt`` holds: ranked as training ranks them (``best_eval_key``:
    the task's ``selection_metric``, Baoding's round rotations, then the return; the return alone
    for a task without one; a record from before the metric was measured below every record with
    it), the first of equals."""
    keys = [best_eval_key(dict(r), selection_metric) for r in records]
    return max(range(len(keys)), key=lambda i: (keys[i], -i))


def plot_learning_curve(
    run_dir: str | pathlib.Path, out: str | pathlib.Path | None = None, selection_metric: str | None = None
) -> pathlib.Path | None:
    """Evaluation mean ± std of the return and each task metric against env steps, ``best.pt``'s
    evaluation marked (``best_evaluation`` by the task's ``selection_metric``).

    Writes ``<run_dir>/learning_curve.png`` unless ``out`` is given; returns the path, or None when
    the run has no evaluation yet.
    """
    records = read_evaluations(run_dir)
    if not records:
        return None
    plt = _pyplot()
    run_dir = pathlib.Path(run_dir)
    metrics = curve_metrics(records)
    steps = np.array([r["env_steps"] for r in records])
    best = best_evaluation(records, selection_metric)
    fig, axes = plt.subplots(1, len(metrics), figsize=(5 * len(metrics), 3.6), squeeze=False)
    for ax, name in zip(axes[0], metrics, strict=True):
        mean = np.array([r[f"{name}_mean"] for r in records])
        std = np.array([r[f"{name}_std"] for r in records])
        ax.plot(steps, mean, color="tab:blue")
        ax.fill_between(steps, mean - std, mean + std, color="tab:blue", alpha=0.2)
        ax.plot(steps[best], mean[best], "o", color="tab:red", label="best.pt")
        ax.set_xlabel("env steps")
        ax.set_ylabel(f"evaluation {name} (mean ± std)")
        ax.grid(alpha=0.3)
    axes[0][0].legend(loc="upper left")
    fig.suptitle(f"{run_dir.name}: {len(records[-1]['per_episode']['return'])} episodes per evaluation")
    fig.tight_layout()
    path = pathlib.Path(out) if out is not None else run_dir / "learning_curve.png"
    with replacing(path) as temporary:
        fig.savefig(temporary, dpi=100, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)
    return path


def plot_variants(
    runs: Mapping[str, Sequence[Sequence[dict]]],
    metric: str,
    out: str | pathlib.Path,
    title: str = "",
    xs: Sequence[str] = ("env_steps",),
    ylabel: str = "",
) -> pathlib.Path:
    """Evaluation ``metric`` against each of ``xs`` (record keys: ``env_steps``, ``train_wall_s``),
    one panel each: per variant, the mean over its runs (seeds) with a band from the lowest to the
    highest run. ``runs`` maps each variant to the evaluation records of each of its runs
    (``read_evaluations``); runs are cut to the evaluations they all have, and an x value is the
    mean over the runs at that evaluation. ``ylabel`` replaces the axis label "evaluation <metric>"."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(xs), figsize=(7 * len(xs), 4.2), squeeze=False)
    for ax, x in zip(axes[0], xs, strict=True):
        for variant, curves in runs.items():
            length = min(len(c) for c in curves)
            if length == 0:
                continue
            position = np.array([[r[x] for r in c[:length]] for c in curves]).mean(axis=0)
            values = np.array([[r[f"{metric}_mean"] for r in c[:length]] for c in curves])
            seeds = f"{len(curves)} seed" + ("" if len(curves) == 1 else "s")
            (line,) = ax.plot(position, values.mean(axis=0), label=f"{variant} ({seeds})")
            ax.fill_between(position, values.min(axis=0), values.max(axis=0), color=line.get_color(), alpha=0.15)
        ax.set_xlabel({"env_steps": "env steps", "train_wall_s": "training wall time (s)"}.get(x, x))
        ax.set_ylabel(ylabel or f"evaluation {metric} (mean over seeds)")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left")
    if title:  # one title over the panels, wrapped to their width (a long list of commits would overlap)
        fig.suptitle(textwrap.fill(title, width=75 * len(xs)))
    fig.tight_layout()
    path = pathlib.Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as temporary:
        fig.savefig(temporary, dpi=100, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)
    return path


def _pyplot():  # matplotlib.pyplot, imported late (headless backend, slow import)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt

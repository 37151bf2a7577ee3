"""Learning curves from a run's ``scalars.csv``."""

from __future__ import annotations

import csv
import pathlib


def read_scalars(run_dir: str | pathlib.Path) -> dict[str, tuple[list[int], list[float]]]:
    """{tag: (env_steps, values)} from ``<run_dir>/scalars.csv``."""
    series: dict[str, tuple[list[int], list[float]]] = {}
    with (pathlib.Path(run_dir) / "scalars.csv").open() as f:
        for row in csv.DictReader(f):
            steps, values = series.setdefault(row["tag"], ([], []))
            steps.append(int(row["env_steps"]))
            values.append(float(row["value"]))
    return series


def plot_learning_curve(run_dir: str | pathlib.Path, out: str | pathlib.Path | None = None) -> pathlib.Path | None:
    """Plot the evaluation curves (mean ± std of each task metric and of the return) vs env steps.

    Writes ``<run_dir>/learning_curve.png`` unless ``out`` is given; returns the path, or None when
    no evaluation round has finished yet.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    run_dir = pathlib.Path(run_dir)
    series = read_scalars(run_dir)
    metrics = sorted(
        tag.removeprefix("eval/").removesuffix("_mean")
        for tag in series
        if tag.startswith("eval/") and tag.endswith("_mean") and tag != "eval/length_mean"
    )
    if not metrics:
        return None
    fig, axes = plt.subplots(1, len(metrics), figsize=(5 * len(metrics), 3.6), squeeze=False)
    for ax, name in zip(axes[0], metrics, strict=True):
        steps, mean = series[f"eval/{name}_mean"]
        _, std = series.get(f"eval/{name}_std", (steps, [0.0] * len(mean)))
        ax.plot(steps, mean, color="tab:blue")
        ax.fill_between(steps, [m - s for m, s in zip(mean, std, strict=True)],
                        [m + s for m, s in zip(mean, std, strict=True)], color="tab:blue", alpha=0.2)  # fmt: skip
        ax.set_xlabel("env steps")
        ax.set_ylabel(f"evaluation {name} (mean ± std)")
        ax.grid(alpha=0.3)
    fig.suptitle(run_dir.name)
    fig.tight_layout()
    path = pathlib.Path(out) if out is not None else run_dir / "learning_curve.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path

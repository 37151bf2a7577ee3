"""Plot a training run's evaluation curve against env steps and wall time (for docs/results.md).

    python benchmarks/learning_curve.py RUN_DIR OUT.png [--metric bounces] [--title TEXT] [--window 10]

Wall time is ``perf/train_wall_s`` when the run logged it, else the sum of each update's
duration (env steps per update / ``perf/steps_per_s``).
"""

from __future__ import annotations

import argparse
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from roto.rl.run_dir import read_scalars

WINDOW = 10  # evaluation rounds in the running mean, unless --window says otherwise
THRESHOLDS = (5, 10, 18, 25)  # running-mean levels whose first crossing the summary reports


def wall_time_at(series: dict[str, tuple[list[int], list[float]]]) -> dict[int, float]:
    """{env steps: training wall seconds so far}, logged or summed from each update's throughput."""
    if "perf/train_wall_s" in series:
        wall_steps, wall = series["perf/train_wall_s"]
    else:
        wall_steps, sps = series["perf/steps_per_s"]
        per_update = wall_steps[0]
        wall, total = [], 0.0
        for rate in sps:
            total += per_update / rate
            wall.append(total)
    return dict(zip(wall_steps, wall, strict=True))


def wall_label(seconds: float, longest: float) -> str:
    """A wall-time tick: minutes, or seconds for a run shorter than 10 minutes."""
    return f"{seconds:.0f} s" if longest < 600 else f"{seconds / 60:.0f} min"


def running_mean(values: list[float], window: int) -> list[float]:
    """Mean of each value and the up to ``window - 1`` before it."""
    return [
        sum(values[max(0, i - window + 1) : i + 1]) / len(values[max(0, i - window + 1) : i + 1])
        for i in range(len(values))
    ]


def draw(
    args: argparse.Namespace, steps: list[int], mean: list[float], smooth: list[float], wall_at: dict[int, float]
) -> None:
    """The curve against env steps, with wall-time ticks on top, saved to ``args.out``."""
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(
        steps,
        mean,
        color="tab:blue",
        alpha=0.35,
        lw=0.8,
        label=f"each evaluation round ({args.metric}, mean of its episodes)",
    )
    ax.plot(steps, smooth, color="tab:blue", lw=2, label=f"running mean of {args.window} rounds")
    ax.set_xlabel("env steps")
    ax.set_ylabel(f"{args.metric} per 10 s episode")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    top = ax.secondary_xaxis("top", functions=(lambda x: x, lambda x: x))
    ticks = ax.get_xticks()
    wall_ticks = [min(wall_at, key=lambda s, t=t: abs(s - t)) for t in ticks if 0 <= t <= max(steps)]
    top.set_xticks(wall_ticks, labels=[wall_label(wall_at[s], max(wall_at.values())) for s in wall_ticks])
    top.set_xlabel("training wall time (rollouts + updates)")
    if args.title:
        ax.set_title(args.title, fontsize=10, pad=30)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


def summarize(steps: list[int], mean: list[float], smooth: list[float], wall_at: dict[int, float]) -> dict:
    """Last / best evaluation, wall time at the last one, and first crossings of the running mean."""
    best = max(range(len(mean)), key=mean.__getitem__)
    summary = {
        "evaluations": len(mean),
        "last_env_steps": steps[-1],
        "last_mean": mean[-1],
        "best_mean": mean[best],
        "best_at_env_steps": steps[best],
        "wall_min_at_last": wall_at[max(s for s in wall_at if s <= steps[-1])] / 60,
    }
    summary["last_running_mean"] = smooth[-1]
    summary["best_running_mean"] = max(smooth)
    first_over = {}
    for threshold in THRESHOLDS:
        hit = next((s for s, m in zip(steps, smooth, strict=True) if m >= threshold), None)
        first_over[threshold] = hit
    summary["first_env_steps_running_mean_at_or_above"] = first_over
    return summary


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("run_dir")
    parser.add_argument("out")
    parser.add_argument("--metric", default="bounces")
    parser.add_argument("--title", default=None)
    parser.add_argument("--window", type=int, default=WINDOW, help="evaluation rounds in the running mean")
    args = parser.parse_args()
    series = read_scalars(args.run_dir)
    steps, mean = series[f"eval/{args.metric}_mean"]
    wall_at = wall_time_at(series)
    smooth = running_mean(mean, args.window)
    draw(args, steps, mean, smooth, wall_at)
    print(json.dumps(summarize(steps, mean, smooth, wall_at)))


if __name__ == "__main__":
    main()

"""Statistics of a few runs, as rliable defines them (Agarwal et al., 2021, "Deep RL at the edge
of the statistical precipice"): interquartile mean, stratified bootstrap intervals, probability
of improvement. Pure numpy; ``tests/olympiad/test_stats.py`` checks them on hand-computed cases.

Scores are arrays of shape (runs, tasks): one score per run (seed) and task.
"""

from __future__ import annotations

import numpy as np


def percentile_interval(values: np.ndarray, confidence: float) -> tuple[float, float]:
    """The central ``confidence`` share of bootstrap statistics ``values`` (reps,): their percentiles."""
    tail = 100.0 * (1.0 - confidence) / 2.0
    low, high = np.percentile(values, [tail, 100.0 - tail])
    return float(low), float(high)


def iqm(scores: np.ndarray) -> float:
    """Interquartile mean of every score: drop the lowest and highest floor(n / 4) of the n values
    (scipy's ``trim_mean(x, 0.25)``, which rliable uses), average the rest.

    Args:
        scores: (runs, tasks) or any shape; all values pooled.
    """
    values = np.sort(np.asarray(scores, dtype=np.float64).ravel())
    cut = int(0.25 * values.size)
    return float(values[cut : values.size - cut].mean())


def stratified_bootstrap_ci(
    scores: np.ndarray, statistic=iqm, reps: int = 2000, confidence: float = 0.95, seed: int = 0
) -> tuple[float, float]:
    """Percentile interval of ``statistic`` over bootstrap resamples that draw runs with replacement
    separately within each task (stratum), as rliable's ``StratifiedBootstrap``.

    Args:
        scores: (runs, tasks).
    """
    scores = np.asarray(scores, dtype=np.float64)
    runs, tasks = scores.shape
    rng = np.random.default_rng(seed)
    picks = rng.integers(0, runs, size=(reps, runs, tasks))  # run index per resample, slot and task
    resampled = np.take_along_axis(np.broadcast_to(scores, (reps, runs, tasks)), picks, axis=1)
    return percentile_interval(np.array([statistic(sample) for sample in resampled]), confidence)


def probability_of_improvement(x: np.ndarray, y: np.ndarray) -> float:
    """P(X > Y): per task, the share of run pairs (x_i, y_j) with x_i > y_j, ties counting one half
    (the Mann-Whitney U statistic over m·n), averaged over tasks.

    Args:
        x: (m runs, tasks) of one agent; y: (n runs, tasks) of the other.
    """
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    greater = (x[:, None, :] > y[None, :, :]).mean(axis=(0, 1))
    ties = (x[:, None, :] == y[None, :, :]).mean(axis=(0, 1))
    return float((greater + 0.5 * ties).mean())


def difference_ci(
    x: np.ndarray, y: np.ndarray, reps: int = 2000, confidence: float = 0.95, seed: int = 0
) -> tuple[float, float]:
    """Percentile bootstrap interval of mean(x) - mean(y), each resampled with replacement on its
    own (two independent groups of runs, e.g. blind and proprio-only agents' seeds).

    Args:
        x: (m,) scores of one agent's runs; y: (n,) of the other's.
    """
    x, y = np.asarray(x, dtype=np.float64).ravel(), np.asarray(y, dtype=np.float64).ravel()
    rng = np.random.default_rng(seed)
    xs = x[rng.integers(0, x.size, size=(reps, x.size))].mean(axis=1)
    ys = y[rng.integers(0, y.size, size=(reps, y.size))].mean(axis=1)
    return percentile_interval(xs - ys, confidence)


def paired_difference_ci(
    x: np.ndarray, y: np.ndarray, reps: int = 2000, confidence: float = 0.95, seed: int = 0
) -> tuple[float, float]:
    """Percentile bootstrap interval of the mean of x_i - y_i over pairs resampled with replacement
    (two agents trained on the same seeds: pair i is seed i of each).

    Args:
        x: (n,) scores of one agent's runs; y: (n,) of the other's on the same seeds, in the same order.
    """
    x, y = np.asarray(x, dtype=np.float64).ravel(), np.asarray(y, dtype=np.float64).ravel()
    if x.shape != y.shape:
        raise ValueError(f"paired scores need one value per seed on both sides, got {x.size} and {y.size}")
    differences = x - y
    rng = np.random.default_rng(seed)
    means = differences[rng.integers(0, differences.size, size=(reps, differences.size))].mean(axis=1)
    return percentile_interval(means, confidence)

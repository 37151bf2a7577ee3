"""The running mean of a metric over the training episodes that ended so far, which the aids that
follow training's progress share (the tolerance curriculum, round swaps armed part way)."""

from __future__ import annotations

import torch

EPISODE_WEIGHT = 0.01
"""Weight of one ended episode in the running mean (about the last hundred episodes count)."""


def fold_ended_episodes(mean: torch.Tensor, metric: torch.Tensor, done: torch.Tensor) -> torch.Tensor:
    """The running mean after the episodes that end now (pure; on the tensors' device, no host read).

    k ended episodes move the mean as k updates of weight ``EPISODE_WEIGHT`` towards their mean
    would; nothing ended, nothing moves.

    Args:
        mean: () float64, the running mean so far.
        metric: (B,) the metric of each world's episode so far.
        done: (B,) bool, the episodes that end now.

    Returns:
        () float64, the new running mean.
    """
    ended = done.to(torch.float64)
    count = ended.sum()
    batch_mean = (metric.to(torch.float64) * ended).sum() / torch.clamp(count, min=1.0)
    weight = 1.0 - (1.0 - EPISODE_WEIGHT) ** count
    return mean + weight * (batch_mean - mean)

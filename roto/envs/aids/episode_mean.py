"""The running mean of a metric over the training episodes that ended so far, which the aids that
follow training's progress share (the tolerance curriculum, round swaps armed part way, turn
shaping's narrowing ``near``), and a setting that narrows with it."""

from __future__ import annotations

from dataclasses import dataclass

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


@dataclass
class Narrowing:
    """A setting that narrows from ``start`` to ``end`` as the running mean of a metric over ended
    training episodes reaches ``target``: ``end + (start - end) * max(0, 1 - mean / target)``, so it
    is ``start`` while the episodes score nothing, ``end`` once they reach ``target`` on average,
    and widens again if they fall back. ``mean`` is a () float64 tensor on the env's device; the
    update never reads it back."""

    start: float
    end: float
    target: float
    mean: torch.Tensor

    def value(self) -> torch.Tensor:
        """() float64, the setting for the running mean now."""
        progress = torch.clamp(1.0 - self.mean / self.target, 0.0, 1.0)
        return self.end + (self.start - self.end) * progress

    def update(self, metric: torch.Tensor, done: torch.Tensor) -> torch.Tensor:
        """Fold in the episodes that end now (``done`` (B,) bool, their ``metric`` (B,)); returns
        the new setting (``fold_ended_episodes``)."""
        self.mean = fold_ended_episodes(self.mean, metric, done)
        return self.value()

    def state_dict(self) -> dict[str, object]:
        return {"mean": self.mean.clone()}

    def load_state_dict(self, state: dict[str, object]) -> None:
        self.mean = state["mean"].clone().to(self.mean.device)

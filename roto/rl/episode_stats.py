"""Means of the training episodes that ended during a rollout, for the training log."""

from __future__ import annotations

from typing import Any

import torch

from roto.envs.episodes import readable


class EpisodeStats:
    """Sums of the training episodes that ended during a rollout, kept on the device until read."""

    def __init__(self, names: tuple[str, ...], device: torch.device) -> None:
        self.names = ("r", "l", *names)
        self.sums = torch.zeros(len(self.names), dtype=torch.float64, device=device)
        self.count = torch.zeros((), dtype=torch.float64, device=device)

    def add(self, info: dict[str, Any]) -> None:
        """Fold in the episodes that ended this step (``info["_episode"]``)."""
        if "episode" in info:
            done = info["_episode"].to(torch.float64)
            episode = info["episode"]
            self.sums += torch.stack([(episode[n].to(torch.float64) * done).sum() for n in self.names])
            self.count += done.sum()

    def read(self) -> dict[str, float]:
        """{"train/episode_<name>": mean} over the ended episodes ({} if none ended); resets the sums."""
        count = float(self.count)
        means = (self.sums / max(count, 1.0)).tolist()
        self.sums.zero_()
        self.count.zero_()
        if count == 0:
            return {}
        tags = [readable(n) for n in self.names]
        return {f"train/episode_{tag}": mean for tag, mean in zip(tags, means, strict=True)}

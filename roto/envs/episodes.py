"""Run a policy until every env has finished a number of episodes, keeping each env's first ones."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import torch
from tqdm import tqdm

EPISODE_NAMES = {"r": "return", "l": "length"}
"""``info["episode"]``'s Gymnasium keys (``RecordEpisodeStatistics``: "r", "l") and what roto's
results, logs and tables call them; task metrics keep their own names."""


def readable(name: str) -> str:
    """The name results use for ``info["episode"]`` key ``name`` ("r" -> "return")."""
    return EPISODE_NAMES.get(name, name)


def first_episodes(
    env: Any,
    act: Callable[[dict[str, torch.Tensor]], torch.Tensor],
    obs: dict[str, torch.Tensor],
    episodes_per_env: int = 1,
    on_done: Callable[[torch.Tensor], None] | None = None,
    progress: bool = False,
) -> dict[str, torch.Tensor]:
    """Step ``env`` with ``act(obs)`` until each env has finished ``episodes_per_env`` episodes.

    Keeping exactly each env's first episodes means short episodes are not over-represented.
    ``on_done(mask (B,))`` is called whenever envs finish (e.g. to reset a policy's own state).

    Returns:
        {"return", "length", and each task metric: (B, episodes_per_env) float64}, in env order.
    """
    if episodes_per_env < 1:
        raise ValueError(f"episodes per env must be >= 1, got {episodes_per_env}")
    n = env.num_envs
    names = ("r", "l", *env.task.metric_names)
    result = {readable(name): torch.full((n, episodes_per_env), float("nan"), dtype=torch.float64) for name in names}
    count = torch.zeros(n, dtype=torch.int64)
    with tqdm(total=n * episodes_per_env, disable=not progress, desc="episodes") as bar:
        while bool((count < episodes_per_env).any()):
            obs, _, _, _, info = env.step(act(obs))
            if "episode" not in info:
                continue
            done = info["_episode"]
            if on_done is not None:
                on_done(done)
            ids = torch.nonzero(done.cpu() & (count < episodes_per_env)).flatten()  # the tally lives on the host
            for name in names:
                result[readable(name)][ids, count[ids]] = info["episode"][name].cpu()[ids].to(torch.float64)
            count[ids] += 1
            bar.update(len(ids))
    return result

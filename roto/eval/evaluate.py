"""Evaluate a policy over whole episodes with the deterministic (mean) action."""

from __future__ import annotations

import math

import torch

from roto.envs.roto_env import RotoEnv
from roto.rl.networks import ActorCritic
from roto.rl.runner import TrainSettings, flatten_obs

MAX_PARALLEL_ENVS = 128


@torch.no_grad()
def evaluate(
    model: ActorCritic, settings: TrainSettings, episodes: int = 100, seed: int = 1_000_000, progress: bool = False
) -> dict[str, object]:
    """Run ``episodes`` full episodes (each env's first, so short episodes are not favoured).

    Returns mean and std of the return, length and every task metric, and the per-episode lists.
    """
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    per_episode: dict[str, list[float]] = {}
    batches = math.ceil(episodes / MAX_PARALLEL_ENVS)
    for batch in range(batches):
        n = min(MAX_PARALLEL_ENVS, episodes - batch * MAX_PARALLEL_ENVS)
        env = RotoEnv(settings.env_config(num_envs=n, seed=seed + batch))
        names = ("r", "l", *env.task.metric_names)
        result = {name: torch.full((n,), float("nan"), dtype=torch.float64) for name in names}
        finished = torch.zeros(n, dtype=torch.bool)
        obs = flatten_obs(env.reset(seed=seed + batch)[0])
        while not bool(finished.all()):
            next_obs, _, _, _, info = env.step(model.act_deterministic(obs))
            if "episode" in info:
                first = info["_episode"] & ~finished
                for name in names:
                    result[name][first] = info["episode"][name][first].to(torch.float64)
                finished |= info["_episode"]
            obs = flatten_obs(next_obs)
        env.close()
        for name in names:
            key = {"r": "return", "l": "length"}.get(name, name)
            per_episode.setdefault(key, []).extend(result[name].tolist())
    summary: dict[str, object] = {"episodes": episodes}
    for key, values in per_episode.items():
        t = torch.tensor(values, dtype=torch.float64)
        summary[f"{key}_mean"] = float(t.mean())
        summary[f"{key}_std"] = float(t.std(unbiased=False))
    summary["per_episode"] = per_episode
    return summary

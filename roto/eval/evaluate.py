"""Evaluate a policy over whole episodes with the deterministic (mean) action."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import torch

from roto.envs.ball_paths import first_episodes_with_paths, for_path_metrics
from roto.envs.config import EnvConfig
from roto.envs.roto_env import RotoEnv
from roto.rl.build import check_policy_fits
from roto.rl.networks import ActorCritic
from roto.rl.run_spec import RunSpec
from roto.rl.torch_threads import single_torch_thread
from roto.tasks import get_task

MAX_PARALLEL_ENVS = 128


@torch.no_grad()
def evaluate(
    model: ActorCritic,
    spec: RunSpec,
    episodes: int = 100,
    seed: int = 1_000_000,
    env_factory: Callable[[EnvConfig], Any] = RotoEnv,
) -> dict[str, object]:
    """Run ``episodes`` full episodes, one per env (so short episodes are not favoured), on the CPU.

    Returns mean and std of the return, length, every task metric and path metric
    (``Task.path_metrics``), and the per-episode lists.
    """
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    per_episode: dict[str, list[float]] = {}
    for batch in range(math.ceil(episodes / MAX_PARALLEL_ENVS)):
        n = min(MAX_PARALLEL_ENVS, episodes - batch * MAX_PARALLEL_ENVS)
        env = env_factory(for_path_metrics(spec.cpu_env_config(num_envs=n, seed=seed + batch)))
        check_policy_fits(model, env)
        obs, _ = env.reset(seed=seed + batch)
        with single_torch_thread(env.device):
            result = first_episodes_with_paths(env, model.act_deterministic, obs)
        env.close()
        for name, values in result.items():
            per_episode.setdefault(name, []).extend(values)
    summary: dict[str, object] = {"episodes": episodes}
    lead = get_task(spec.env.task).selection_metric  # Baoding's round rotations first, roto's count after
    for key, values in sorted(per_episode.items(), key=lambda item: item[0] != lead):
        t = torch.tensor(values, dtype=torch.float64)
        summary[f"{key}_mean"] = float(t.mean())
        summary[f"{key}_std"] = float(t.std(unbiased=False))
    summary["per_episode"] = per_episode
    return summary

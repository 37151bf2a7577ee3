"""Evaluate a policy over whole episodes with the deterministic (mean) action."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import torch

from roto.envs.config import EnvConfig
from roto.envs.episodes import first_episodes
from roto.envs.roto_env import RotoEnv
from roto.eval.ball_paths import BallPathRecorder, with_ball_state
from roto.rl.networks import ActorCritic
from roto.rl.settings import TrainSettings
from roto.rl.torch_threads import single_torch_thread
from roto.tasks import get_task

MAX_PARALLEL_ENVS = 128


@torch.no_grad()
def evaluate(
    model: ActorCritic,
    settings: TrainSettings,
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
    measures_path = bool(get_task(settings.env.task).path_metric_names)
    per_episode: dict[str, list[float]] = {}
    for batch in range(math.ceil(episodes / MAX_PARALLEL_ENVS)):
        n = min(MAX_PARALLEL_ENVS, episodes - batch * MAX_PARALLEL_ENVS)
        config = settings.cpu_env_config(num_envs=n, seed=seed + batch)
        env = env_factory(with_ball_state(config) if measures_path else config)
        task = env.task  # the env's own: a test double's measures no path
        act = BallPathRecorder(model.act_deterministic, len(env.balls)) if task.path_metric_names else None
        obs, _ = env.reset(seed=seed + batch)
        with single_torch_thread(env.device):
            result = first_episodes(env, act or model.act_deterministic, obs)
        env.close()
        paths = act.path_metrics(task, result["length"][:, 0]) if act is not None else {}
        for name, values in [*((k, v[:, 0].tolist()) for k, v in result.items()), *paths.items()]:
            per_episode.setdefault(name, []).extend(values)
    summary: dict[str, object] = {"episodes": episodes}
    for key, values in per_episode.items():
        t = torch.tensor(values, dtype=torch.float64)
        summary[f"{key}_mean"] = float(t.mean())
        summary[f"{key}_std"] = float(t.std(unbiased=False))
    summary["per_episode"] = per_episode
    return summary

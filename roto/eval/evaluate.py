"""Evaluate a policy over whole episodes: roto's evaluation protocol.

``evaluate_policy`` runs any act function (a roto checkpoint's deterministic action, or another
method's policy) on the benchmark's own task: ``episodes`` episodes, one per env (so short episodes
are not favoured), on the CPU, batch b of at most 128 envs reset with seed ``seed + b``, no
training aids. ``evaluate`` is that protocol for a roto policy and the run it trained in. A
submission to roto's table (docs/submissions.md) holds what ``evaluate_policy`` returns for each
of its seeds.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import torch

from roto.envs.ball_paths import first_episodes_with_paths, for_path_metrics
from roto.envs.config import EnvConfig
from roto.envs.observations import OBS_MODES
from roto.envs.roto_env import RotoEnv
from roto.eval.protocol import EVAL_EPISODES, EVAL_SEED, MAX_PARALLEL_ENVS
from roto.rl.build import check_policy_fits
from roto.rl.networks import ActorCritic
from roto.rl.run_spec import RunSpec
from roto.rl.torch_threads import single_torch_thread
from roto.tasks import get_task

Act = Callable[[dict[str, torch.Tensor]], torch.Tensor]
"""obs {group: (B, ...)} -> actions (B, num_actions) in [-1, 1]."""


def policy_groups(act: Act, config: EnvConfig) -> Act:
    """``act`` fed only the observation groups of ``config``'s obs mode (the evaluator's env also
    returns the balls' state where the task measures their paths, which a blind policy must not read)."""
    groups = (*OBS_MODES[config.obs_mode], *config.extra_groups)

    def act_on_groups(obs: dict[str, torch.Tensor]) -> torch.Tensor:
        return act({name: obs[name] for name in groups if name in obs})

    return act_on_groups


@torch.no_grad()
def evaluate_policy(
    act: Act,
    config: EnvConfig,
    episodes: int = EVAL_EPISODES,
    seed: int = EVAL_SEED,
    env_factory: Callable[[EnvConfig], Any] = RotoEnv,
    check: Callable[[Any], None] | None = None,
) -> dict[str, object]:
    """Run ``episodes`` full episodes of ``config``'s task, hand and obs mode with ``act``, on the
    CPU and without training aids whatever ``config`` says (its ``num_envs`` and ``seed`` are the
    protocol's). ``check(env)``, if given, runs on each batch's env before the first step.

    Returns:
        {"episodes", "seed", "<measure>_mean", "<measure>_std" (population) for the return, the length,
        every task metric and path metric (``Task.path_metrics``), the task's ``selection_metric``
        first, and "per_episode": {measure: one value per episode}}.
    """
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    config = config.without_training_aids()
    per_episode: dict[str, list[float]] = {}
    for batch in range(math.ceil(episodes / MAX_PARALLEL_ENVS)):
        n = min(MAX_PARALLEL_ENVS, episodes - batch * MAX_PARALLEL_ENVS)
        batch_config = dataclasses.replace(config, num_envs=n, seed=seed + batch, backend="cpu", device="cpu")
        env = env_factory(for_path_metrics(batch_config))
        if check is not None:
            check(env)
        obs, _ = env.reset(seed=seed + batch)
        with single_torch_thread(env.device):
            result = first_episodes_with_paths(env, policy_groups(act, batch_config), obs)
        env.close()
        for name, values in result.items():
            per_episode.setdefault(name, []).extend(values)
    summary: dict[str, object] = {"episodes": episodes, "seed": seed}
    lead = get_task(config.task).selection_metric  # Baoding's round rotations first, roto's count after
    for key, values in sorted(per_episode.items(), key=lambda item: item[0] != lead):
        t = torch.tensor(values, dtype=torch.float64)
        summary[f"{key}_mean"] = float(t.mean())
        summary[f"{key}_std"] = float(t.std(unbiased=False))
    summary["per_episode"] = per_episode
    return summary


def evaluate(
    model: ActorCritic,
    spec: RunSpec,
    episodes: int = EVAL_EPISODES,
    seed: int = EVAL_SEED,
    env_factory: Callable[[EnvConfig], Any] = RotoEnv,
) -> dict[str, object]:
    """``evaluate_policy`` of a roto policy's deterministic (mean) action on its run's env
    (``RunSpec.cpu_env_config``), refusing a policy whose sizes do not fit it (``check_policy_fits``)."""
    return evaluate_policy(
        model.act_deterministic,
        spec.cpu_env_config(),
        episodes,
        seed,
        env_factory,
        check=lambda env: check_policy_fits(model, env),
    )

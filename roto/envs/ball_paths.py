"""The balls' path through each evaluation episode, for a task's path metrics (``Task.path_metrics``).

The evaluation envs also return the ``privileged`` group (the balls' state, which the policy never
reads), and the policy's act function is wrapped to keep the balls' centres from each observation
it answers, so the path is the one the policy saw, with no change to the episodes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import torch

from roto.envs.config import EnvConfig
from roto.envs.episodes import first_episodes
from roto.envs.observations import OBS_MODES, ball_positions
from roto.tasks import get_task
from roto.tasks.base import Task

BALL_GROUP = "privileged"


def with_ball_state(config: EnvConfig) -> EnvConfig:
    """``config`` with the ``privileged`` group among the groups its envs return."""
    if BALL_GROUP in OBS_MODES[config.obs_mode] or BALL_GROUP in config.extra_groups:
        return config
    return dataclasses.replace(config, extra_groups=(*config.extra_groups, BALL_GROUP))


def for_path_metrics(config: EnvConfig) -> EnvConfig:
    """An evaluation env config: with the balls' state where its task has path metrics."""
    return with_ball_state(config) if get_task(config.task).path_metric_names else config


class BallPathRecorder:
    """An act function that keeps the balls' centres of every observation before acting on it.

    Args:
        act: the policy's act function (obs -> actions).
        n_ball: balls in the task's scene.
    """

    def __init__(self, act: Callable[[dict[str, torch.Tensor]], torch.Tensor], n_ball: int) -> None:
        self.act, self.n_ball = act, n_ball
        self.positions: list[torch.Tensor] = []  # on the envs' device until the episodes end

    def __call__(self, obs: dict[str, torch.Tensor]) -> torch.Tensor:
        self.positions.append(ball_positions(obs[BALL_GROUP], self.n_ball).clone())
        return self.act(obs)

    def path_metrics(
        self, task: Task, lengths: torch.Tensor, metrics: Mapping[str, Sequence[float] | torch.Tensor]
    ) -> dict[str, list[float]]:
        """Each env's first episode's ``task.path_metrics``, from its first ``lengths[i]`` observations.

        Args:
            lengths: (B,) steps of each env's first episode; observation 0 is the one after its reset.
            metrics: {name: B values (a list or a (B,) array)} each of the task's ``metric_names`` at
                that episode's end.

        Returns:
            {name: B values}, in env order.
        """
        path = torch.stack(self.positions).cpu()  # (steps, B, n_ball, 3)
        ends = {name: torch.as_tensor(values).tolist() for name, values in metrics.items()}
        rows = [
            task.path_metrics(path[: int(length), i], {name: values[i] for name, values in ends.items()})
            for i, length in enumerate(lengths.tolist())
        ]
        return {name: [row[name] for row in rows] for name in task.path_metric_names}


def first_episodes_with_paths(
    env: Any, act: Callable[[dict[str, torch.Tensor]], torch.Tensor], obs: dict[str, torch.Tensor]
) -> dict[str, list[float]]:
    """The first episode of each env (``first_episodes``) as lists of the return, length and task
    metrics, and of the env's task's path metrics where it has any (its envs must then return
    the ``privileged`` group: ``for_path_metrics``)."""
    names = env.task.path_metric_names
    recorder = BallPathRecorder(act, len(env.balls)) if names else None
    result = first_episodes(env, recorder or act, obs)
    per_episode = {name: values[:, 0].tolist() for name, values in result.items()}
    if recorder is not None:
        ends = {name: per_episode[name] for name in env.task.metric_names}
        per_episode.update(recorder.path_metrics(env.task, result["length"][:, 0], ends))
    return per_episode

"""The balls' path through each evaluation episode, for a task's path metrics (``Task.path_metrics``).

The evaluation envs also return the ``privileged`` group (the balls' state, which the policy never
reads), and the policy's act function is wrapped to keep the balls' centres from each observation
it answers, so the path is the one the policy saw, with no change to the episodes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import torch

from roto.envs.config import EnvConfig
from roto.envs.observations import OBS_MODES, ball_positions
from roto.tasks.base import Task

BALL_GROUP = "privileged"


def with_ball_state(config: EnvConfig) -> EnvConfig:
    """``config`` with the ``privileged`` group among the groups its envs return."""
    if BALL_GROUP in OBS_MODES[config.obs_mode] or BALL_GROUP in config.extra_groups:
        return config
    return dataclasses.replace(config, extra_groups=(*config.extra_groups, BALL_GROUP))


class BallPathRecorder:
    """An act function that keeps the balls' centres of every observation before acting on it.

    Args:
        act: the policy's act function (obs -> actions).
        n_ball: balls in the task's scene.
    """

    def __init__(self, act: Callable[[dict[str, torch.Tensor]], torch.Tensor], n_ball: int) -> None:
        self.act, self.n_ball = act, n_ball
        self.positions: list[torch.Tensor] = []

    def __call__(self, obs: dict[str, torch.Tensor]) -> torch.Tensor:
        self.positions.append(ball_positions(obs[BALL_GROUP], self.n_ball).cpu())
        return self.act(obs)

    def path_metrics(self, task: Task, lengths: torch.Tensor) -> dict[str, list[float]]:
        """Each env's first episode's ``task.path_metrics``, from its first ``lengths[i]`` observations.

        Args:
            lengths: (B,) steps of each env's first episode; observation 0 is the one after its reset.

        Returns:
            {name: B values}, in env order.
        """
        path = torch.stack(self.positions)  # (steps, B, n_ball, 3)
        rows = [task.path_metrics(path[: int(length), i]) for i, length in enumerate(lengths.tolist())]
        return {name: [row[name] for row in rows] for name in task.path_metric_names}

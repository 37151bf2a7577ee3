"""What an env observes: the groups it returns, one frame's size per group, the spaces, the state
selections each frame is made from, and the stack of the last k frames."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import torch

from roto.envs.config import EnvConfig
from roto.envs.frames import observation_frame
from roto.envs.indices import SceneIndices
from roto.envs.observations import OBS_GROUPS, OBS_MODES, FrameStack, task_frame
from roto.envs.selections import Selected, Selections
from roto.robots.spec import RobotSpec
from roto.tasks.base import Task


def frame_sizes(
    groups: tuple[str, ...], robot: RobotSpec, task: Task, num_taxels: int, num_balls: int
) -> dict[str, int]:
    """{group: features of one frame} for ``groups``: touch bits per link (and taxel), proprio
    (observed joints' positions and velocities, the joint targets and the last action), each
    ball's position and velocity, the task's features and the time left."""
    n_obs, n_act = len(robot.observed_joints), robot.num_actions
    sizes = {
        "tactile": len(robot.tactile_links) + num_taxels,
        "proprio": 2 * n_obs + 2 * n_act,
        "privileged": 6 * num_balls,
        "task": task.observation_size + 1,
    }
    return {group: sizes[group] for group in groups}


class Observer:
    """The observation side of an env.

    Attributes:
        groups: the groups the env returns (its obs mode's and the extra ones, in ``OBS_GROUPS`` order).
        frame_sizes: {group: features of one frame}.
        observation_space: the stacked observation's space (``config.frame_stack`` frames a group).
        selections: the state columns each frame is made from (``roto.envs.selections``).
        stack: the last ``config.frame_stack`` frames of every world.
    """

    def __init__(
        self, config: EnvConfig, task: Task, robot: RobotSpec, indices: SceneIndices, num_taxels: int, num_balls: int
    ) -> None:
        """``indices``: the scene's index sets on the env's device; ``num_taxels``: the scene's
        taxel sensors (``touch="taxels"``); ``num_balls``: the task's balls."""
        wanted = set(OBS_MODES[config.obs_mode]) | set(config.extra_groups)
        self.groups = tuple(group for group in OBS_GROUPS if group in wanted)
        self.config, self.task, self.indices = config, task, indices
        self.frame_sizes = frame_sizes(self.groups, robot, task, num_taxels, num_balls)
        self.observation_space = gym.spaces.Dict(
            {
                name: gym.spaces.Box(-np.inf, np.inf, (config.frame_stack * size,), np.float32)
                for name, size in self.frame_sizes.items()
            }
        )
        self.stack = FrameStack(config.frame_stack)
        self.selections = Selections(indices, indices.obs_lo.device, taxels=config.touch == "taxels")  # env's device

    def frame(
        self, selected: Selected, target: torch.Tensor, last_action: torch.Tensor, task: torch.Tensor | None
    ) -> dict[str, torch.Tensor]:
        """The groups of one frame (``roto.envs.frames.observation_frame``)."""
        idx = self.indices
        return observation_frame(self.groups, self.config, selected, idx.obs_lo, idx.obs_hi, target, last_action, task)

    def task_frame(self, state: object, length: torch.Tensor) -> torch.Tensor | None:
        """The ``task`` group's frame of task state ``state`` after ``length`` (B,) steps; None when
        the env returns no task group."""
        if "task" not in self.groups:
            return None
        return task_frame(self.task.observation(state), length, self.config.episode_steps)

"""One observation frame, every group the env returns, from a batch of state selections."""

from __future__ import annotations

import torch

from roto.envs.config import EnvConfig
from roto.envs.observations import privileged_frame, proprio_frame, tactile_frame
from roto.envs.selections import Selected


def observation_frame(
    groups: tuple[str, ...],
    config: EnvConfig,
    selected: Selected,
    obs_lo: torch.Tensor,
    obs_hi: torch.Tensor,
    target: torch.Tensor,
    last_action: torch.Tensor,
    task: torch.Tensor | None,
) -> dict[str, torch.Tensor]:
    """One frame per group in ``groups`` from (n, ·) state selections; NaN and inf read as 0 (a
    diverged world's last frame); the tactile bits are finite by construction.

    Args:
        groups: the groups to make, in the env's order.
        config: the env's touch mode and threshold.
        selected: the state columns of n worlds.
        obs_lo, obs_hi: (n_obs,) the observed joints' limits.
        target: (n, n_act) joint targets; last_action: (n, n_act) the raw actions.
        task: (n, dim) the ``task`` group's frame (``observations.task_frame``), None without it.

    Returns:
        group -> (n, dim) float32.
    """
    frame: dict[str, torch.Tensor] = {}
    if "tactile" in groups:
        frame["tactile"] = tactile_frame(
            config.touch, selected.tactile_force, selected.taxel_force, config.tactile_threshold
        )
    frame["proprio"] = proprio_frame(
        selected.obs_qpos, selected.obs_qvel, obs_lo, obs_hi, target, selected.act_qpos, last_action
    ).nan_to_num_(nan=0.0, posinf=0.0, neginf=0.0)
    if "privileged" in groups:
        frame["privileged"] = privileged_frame(selected.ball_pos, selected.ball_vel).nan_to_num_(
            nan=0.0, posinf=0.0, neginf=0.0
        )
    if task is not None:
        frame["task"] = task
    return {name: frame[name] for name in groups}

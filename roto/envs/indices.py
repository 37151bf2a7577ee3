"""Where the env's quantities live in MuJoCo's flat arrays: column selections of qpos, qvel and
sensordata, joint limits and the default pose, as tensors on the env's device."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from roto.envs.columns import Columns
from roto.robots.spec import RobotSpec
from roto.sim.scene import SceneLayout


@dataclass(frozen=True)
class SceneIndices:
    """Column selections of qpos / qvel / sensordata and constants, on the env's device."""

    act_qpos: Columns
    obs_qpos: Columns
    obs_qvel: Columns
    obs_lo: torch.Tensor
    obs_hi: torch.Tensor
    ctrl_lo: torch.Tensor
    ctrl_hi: torch.Tensor
    ball_pos: Columns  # (n_ball, 3) qpos indices of each ball's centre
    ball_vel: Columns  # (n_ball, 3) qvel indices of each ball's linear velocity
    tactile_force: Columns  # (n_links,) each link's strongest normal force; force touch: (n_links, 3) net force
    ball_force: Columns  # (n_ball,) sensordata index of each ball-hand normal force
    taxels: Columns  # (n_taxels,) sensordata index of each taxel's normal force (empty without taxels)
    self_contact: Columns  # (2,) sensordata indices of the hand's self-contact (found, distance m)
    ball_clearance: Columns  # (n_ball, 2) sensordata indices of each ball's deepest contact (found, distance m)
    default_qpos: torch.Tensor  # (1, nq), the balls' quaternions at identity
    coupled_driven: Columns
    coupled_driver: Columns
    coupled_ratio: torch.Tensor
    coupled_lo: torch.Tensor
    coupled_hi: torch.Tensor

    @classmethod
    def from_layout(
        cls, layout: SceneLayout, robot: RobotSpec, model: Any, device: torch.device, touch: str = "binary"
    ) -> SceneIndices:
        def t(array: Any, dtype: torch.dtype = torch.int64) -> torch.Tensor:
            return torch.as_tensor(np.asarray(array), dtype=dtype, device=device)

        def c(array: Any) -> Columns:
            return Columns.of(array, device)

        f64 = torch.float64
        driven = [model.joint(j).qposadr[0] for j in robot.coupled_joints]
        driver = [model.joint(d).qposadr[0] for d, _ in robot.coupled_joints.values()]
        driven_ids = [model.joint(j).id for j in robot.coupled_joints]
        default = layout.default_qpos.copy()
        default[layout.ball_qpos[:, None] + 3 + np.arange(4)] = [1.0, 0.0, 0.0, 0.0]  # every reset starts unrotated
        for j, (d, ratio) in robot.coupled_joints.items():
            default[model.joint(j).qposadr[0]] = np.clip(
                ratio * default[model.joint(d).qposadr[0]], *model.jnt_range[model.joint(j).id]
            )
        return cls(
            act_qpos=c(layout.act_qpos),
            obs_qpos=c(layout.obs_qpos),
            obs_qvel=c(layout.obs_qvel),
            obs_lo=t(layout.obs_lo, f64),
            obs_hi=t(layout.obs_hi, f64),
            ctrl_lo=t(layout.ctrl_lo, f64),
            ctrl_hi=t(layout.ctrl_hi, f64),
            ball_pos=c(layout.ball_qpos[:, None] + np.arange(3)),
            ball_vel=c(layout.ball_qvel[:, None] + np.arange(3)),
            tactile_force=c(
                layout.tactile_sensor[:, None] + 1 + np.arange(3) if touch == "force" else layout.tactile_sensor + 1
            ),
            ball_force=c(layout.ball_contact_sensor + 1),
            taxels=c(layout.taxel_sensor),
            self_contact=c([layout.self_contact_sensor, layout.self_contact_sensor + 1]),
            ball_clearance=c(layout.ball_clearance_sensor[:, None] + np.arange(2)),
            default_qpos=t(default, f64)[None],
            coupled_driven=c(driven),
            coupled_driver=c(driver),
            coupled_ratio=t([r for _, r in robot.coupled_joints.values()], f64),
            coupled_lo=t(model.jnt_range[driven_ids, 0] if driven_ids else [], f64),
            coupled_hi=t(model.jnt_range[driven_ids, 1] if driven_ids else [], f64),
        )

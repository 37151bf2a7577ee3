"""Episode starts of an env (``StartSource``: ``RotoEnv``'s public parts): the task's own, and the
first frame of any start.

The task's own start is the hand at its default pose plus joint noise with the task's balls
placed, at rest, redrawn until valid (``roto.envs.start_pool.draw_valid_starts``); training aids
may start episodes elsewhere (``roto.envs.aids``).
"""

from __future__ import annotations

import functools
from typing import Any, Protocol

import mujoco
import torch

from roto.envs.config import EnvConfig
from roto.envs.indices import SceneIndices
from roto.envs.selections import Selected, Selections
from roto.envs.start_pool import contact_depth, draw_valid_starts
from roto.robots.spec import RobotSpec
from roto.sim.backend import Backend
from roto.tasks.base import Task, uniform


class StartSource(Protocol):
    """What drawing starts reads of an env (``RotoEnv`` is one): its public parts."""

    backend: Backend
    config: EnvConfig
    device: torch.device
    groups: tuple[str, ...]
    indices: SceneIndices
    model: mujoco.MjModel
    num_actions: int
    robot: RobotSpec
    selections: Selections
    task: Task
    task_state: Any

    def observation_frame(
        self, selected: Selected, target: torch.Tensor, last_action: torch.Tensor, task: torch.Tensor | None
    ) -> dict[str, torch.Tensor]: ...

    def task_state_frame(self, state: object = None, length: torch.Tensor | None = None) -> torch.Tensor | None: ...


def draw_starts(env: StartSource, n: int, generator: torch.Generator) -> dict[str, torch.Tensor]:
    """n valid episode starts of the task's own (``draw_candidates``, redrawn until valid): rows as
    ``draw_candidates``' without the depths. A training aid may draw others instead
    (``roto.envs.aids.TrainingAid.draw_starts``)."""
    return draw_valid_starts(functools.partial(draw_candidates, env, generator=generator), n, env.robot.name)


def first_frame(
    env: StartSource, qpos: torch.Tensor, qvel: torch.Tensor, target: torch.Tensor, task_rows: dict[str, torch.Tensor]
) -> tuple[dict[str, torch.Tensor], torch.Tensor]:
    """The first observation frame ("frame/<group>" -> (n, dim)) of n starts, and their sensor
    values (n, nsensordata); ``task_rows`` are the task state fields the starts begin with (the
    others, and all without them, as a reset leaves them)."""
    device = env.device
    n = len(qpos)
    sensors = env.backend.sensors_at(qpos, qvel, target).to(device, torch.float64)
    selected = env.selections.select(qpos, qvel, sensors[:, None])
    last_action = torch.zeros(n, env.num_actions, dtype=torch.float32, device=device)
    task_frame = None
    if "task" in env.groups:
        first = env.task.init_state(env.robot, n, device)
        for name, rows in task_rows.items():
            setattr(first, name, rows.to(getattr(first, name).dtype))
        task_frame = env.task_state_frame(first, torch.zeros(n, dtype=torch.int64, device=device))
    frame = env.observation_frame(selected, target, last_action, task_frame)
    return {f"frame/{name}": value for name, value in frame.items()}, sensors


def draw_candidates(env: StartSource, n: int, generator: torch.Generator) -> dict[str, torch.Tensor]:
    """n candidates of the task's own starts: the hand at its default pose plus noise, the task's
    balls placed, at rest; their qpos (n, nq), qvel (n, nv, zero), joint targets (n, n_act), first
    frame ("frame/<group>"), and the depth (m) of the hand's deepest self-contact ("penetration",
    (n,)) and of the balls' deepest contact with the hand or each other ("ball_penetration", (n,)).
    Random draws come from ``generator``."""
    idx, device = env.indices, env.device
    qpos = idx.default_qpos.expand(n, -1).clone()
    noise = uniform(generator, (n, env.num_actions), env.config.reset_joint_noise, device)
    idx.act_qpos.put(qpos, torch.clamp(idx.act_qpos.take(qpos) + noise, idx.ctrl_lo, idx.ctrl_hi))
    idx.coupled_driven.put(
        qpos, torch.clamp(idx.coupled_driver.take(qpos) * idx.coupled_ratio, idx.coupled_lo, idx.coupled_hi)
    )
    ball_pos = env.task.initial_ball_positions(env.task_state, n, generator)
    idx.ball_pos.put(qpos, ball_pos.to(qpos.dtype))  # the default pose holds the balls' identity quaternions
    qvel = qpos.new_zeros(n, env.model.nv)
    target = idx.act_qpos.take(qpos).clone()
    frame, sensors = first_frame(env, qpos, qvel, target, {})
    return {
        "qpos": qpos,
        "qvel": qvel,
        "target": target,
        **frame,
        "penetration": contact_depth(idx.self_contact.take(sensors)),
        "ball_penetration": contact_depth(idx.ball_clearance.take(sensors)).amax(dim=1),  # deepest ball
    }

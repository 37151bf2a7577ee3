"""The batched roto environment: B worlds of one (task, robot) pair, torch in and out.

One ``step`` runs, in this order (DESIGN §1):
  action -> joint targets -> backend (substeps on B worlds) -> task counters, rewards,
  terminations -> observation frame -> frame stack -> auto-reset of finished worlds (same step).
"""

from __future__ import annotations

import dataclasses
import functools
import operator
from typing import Any, ClassVar, TypeVar

import gymnasium as gym
import mujoco
import numpy as np
import torch

from roto.envs.aids.aid_set import AidSet
from roto.envs.aids.build import build_aids
from roto.envs.aids.protocol import AidHost, StepContext, TrainingAid
from roto.envs.config import EnvConfig
from roto.envs.control import action_to_target, smooth_target, target_to_action
from roto.envs.episode_book import EpisodeBook
from roto.envs.episode_starts import EpisodeStarts
from roto.envs.indices import SceneIndices
from roto.envs.observer import Observer
from roto.envs.selections import Selected
from roto.envs.spaces import BoundedBox
from roto.envs.start_pool import check_balls_start_clear
from roto.envs.step_checks import StepChecks
from roto.robots import get_robot
from roto.robots.spec import RobotSpec
from roto.sim.backend import Backend
from roto.sim.host_sync import deliberate_host_sync, resolve_device
from roto.sim.make_backend import make_backend
from roto.sim.scene import build_scene
from roto.tasks import get_task
from roto.tasks.base import TaskInputs

AidT = TypeVar("AidT", bound=TrainingAid)


def backend_for(config: EnvConfig, model: mujoco.MjModel) -> Backend:
    """The physics backend ``config`` names for ``model``; Warp's fixed per-world contact and
    constraint buffers are roto's measured figures for the pair unless the config gives them."""
    capacity = {}
    if config.backend == "warp":
        nconmax, njmax = get_robot(config.robot).tasks[config.task].warp_capacity
        capacity = {"nconmax": config.nconmax or nconmax, "njmax": config.njmax or njmax}
    return make_backend(
        config.backend,
        model,
        config.num_envs,
        substeps=config.substeps,
        threads=config.threads,
        device=config.device,
        **capacity,
    )


class RotoEnv:
    """B parallel worlds of one roto task on one robot (see ``roto.make``), composed of public
    parts: the scene's index sets (``indices``), the observation side (``observer``: groups, frame
    stack, spaces), the episode starts (``starts``), the episodes' statistics (``episodes``), the
    training aids (``aids``) and when a step reads the device (``checks``)."""

    metadata: ClassVar[dict[str, Any]] = {"autoreset_mode": gym.vector.AutoresetMode.SAME_STEP}

    def __init__(self, config: EnvConfig) -> None:
        config.check_available()
        self.config = config
        self.task = get_task(config.task)
        self.robot: RobotSpec = get_robot(config.robot)
        self.num_envs, self.num_actions = config.num_envs, self.robot.num_actions
        self.device = resolve_device(config.device)
        self.balls = self.task.balls(self.robot)
        self.model, self.layout = build_scene(self.robot, self.balls, config.touch)
        self.backend = backend_for(config, self.model)
        self.indices = SceneIndices.from_layout(self.layout, self.robot, self.model, self.device, config.touch)
        self.task_state = self.task.init_state(self.robot, self.num_envs, self.device)
        taxels, balls = len(self.layout.taxel_sensor), len(self.balls)
        self.observer = Observer(config, self.task, self.robot, self.indices, taxels, balls)
        self.groups, self.stack, self.selections = self.observer.groups, self.observer.stack, self.observer.selections
        self.frame_sizes, self.observation_space = self.observer.frame_sizes, self.observer.observation_space
        self.action_space = BoundedBox(-1.0, 1.0, (self.num_actions,), np.float32)
        self.episodes = EpisodeBook.empty(self.num_envs, self.device)
        # each world's joint targets (B, n_act) float64 and last action (B, n_act) float32; the
        # single-world step writes both in place
        self.joint_targets = torch.zeros(self.num_envs, self.num_actions, dtype=torch.float64, device=self.device)
        self.last_action = torch.zeros(self.num_envs, self.num_actions, dtype=torch.float32, device=self.device)
        self._zero_qvel = torch.zeros(self.num_envs, self.model.nv, dtype=torch.float64, device=self.device)
        self.starts = EpisodeStarts(self, config.seed)
        host = AidHost(config, self.task, self.task_state, self.robot, self.device, self.model, self.starts.first_frame)
        self.aids = AidSet(build_aids(host))  # training only: none in an evaluation env
        self.starts.draw_through(self.aids)
        self.checks = StepChecks(self.device)
        self._needs_reset = True
        # a task whose balls start inside the hand is refused now, not after rounds of redrawing
        check_balls_start_clear(self.starts.candidates, self.robot.name, self.task.name, self.device)

    # ------------------------------------------------------------------ public API

    def reset(self, seed: int | None = None) -> tuple[dict[str, torch.Tensor], dict[str, Any]]:
        """Reset every world; returns (obs, info). ``seed`` re-seeds the reset noise."""
        if seed is not None:
            self.starts.reseed(seed)
        self.starts.pool.clear()  # a reset, seeded or not, starts from freshly drawn starts
        with deliberate_host_sync(self.device):  # a reset draws starts, reading the pool as it goes
            self.starts.pool.ensure(self.checks.every * self.num_envs)
        self.checks.since = 0
        frame = self._reset_where(torch.ones(self.num_envs, dtype=torch.bool, device=self.device))
        if self.checks.sync_free:  # read only every few steps: cover every world ending on each of them
            with deliberate_host_sync(self.device):
                self.starts.pool.ensure(self.checks.every * self.num_envs)
        self.stack.reset(frame)
        self.aids.on_reset()
        self._needs_reset = False
        return self.stack.observation(), {}

    def step(
        self, action: torch.Tensor
    ) -> tuple[dict[str, torch.Tensor], torch.Tensor, torch.Tensor, torch.Tensor, dict[str, Any]]:
        """Advance every world one control step; finished worlds are reset within the same step.

        Returns (obs, reward (B,), terminated (B,), truncated (B,), info). For worlds that finished,
        ``info["final_obs"]`` holds their last observation, ``info["episode"]`` their return ``r``,
        length ``l``, task metrics and ``time_out`` (valid where ``info["_episode"]`` is True).
        """
        if self._needs_reset:
            raise RuntimeError("call reset() before the first step()")
        action = self.checks.action(action, (self.num_envs, self.num_actions), self.device)
        target = action_to_target(action.to(torch.float64), self.indices.ctrl_lo, self.indices.ctrl_hi)
        self.joint_targets = smooth_target(target, self.joint_targets, self.config.action_smoothing)
        self.last_action = action.to(torch.float32, copy=True)  # never alias the caller's tensor

        sim = self.backend.step(self.joint_targets)
        selected = self.selections.of(sim)
        diverged = sim.diverged.to(self.device)
        result = self.task.step(self.task_state, self._task_inputs(selected))
        reward = functools.reduce(operator.add, result.reward_terms.values()).masked_fill(diverged, 0.0)
        self.episodes.add(reward, result.reward_terms)
        terminated = result.terminated | diverged
        truncated = (self.episodes.length >= self.config.episode_steps) & ~terminated

        self.stack.push(self.observation_frame(selected, self.joint_targets, self.last_action, self.task_state_frame()))
        obs = self.stack.observation()
        done = terminated | truncated
        if self.aids.watching:  # training aids fed by the headline metric, before the resets
            metric, length = self.task.metrics(self.task_state)[self.task.headline_metric], self.episodes.length
            seen = StepContext(sim.qpos, sim.qvel, self.joint_targets, self.task_state, metric, length, done)
            self.aids.observe(seen)
        info: dict[str, Any] = {"reward_terms": result.reward_terms, "nonfinite": diverged}
        # a step without resets skips them, unless asking would wait for the device: then the reset
        # runs every step, masked (a world that did not finish is left as it was)
        if self.checks.sync_free or self._starts_ready_for(done):
            info["final_obs"], info["_final_obs"] = obs, done
            info["episode"] = self.episodes.info(truncated, self.task.metrics(self.task_state))
            info["_episode"] = done
            self.episodes.nonfinite_resets += diverged.sum()  # stays on the device until someone reads it
            self.stack.reset_where(self._reset_where(done), done)
            obs = self.stack.observation()
        if self.checks.step_done():
            self._periodic_check()
        return obs, reward.to(torch.float32), terminated, truncated, info

    def close(self) -> None:
        """Release the backend's threads."""
        self.backend.close()

    def state_dict(self) -> dict[str, Any]:
        """Everything that decides the env's future: physics, task counters, frame stack, RNG, pooled
        starts, the aids' state. ``load_state_dict`` of it on an env built from the same config
        continues bit-identically (exact resume)."""
        return {
            "physics": torch.from_numpy(self.backend.physics_state()),
            "task": {f.name: getattr(self.task_state, f.name).clone() for f in dataclasses.fields(self.task_state)},
            "frames": self.stack.state_dict(),
            **self.episodes.state_dict(),
            "target": self.joint_targets.clone(),
            "last_action": self.last_action.clone(),
            **self.starts.state_dict(),
            "needs_reset": self._needs_reset,
            "since_check": self.checks.since,
            **self.aids.state_dict(),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what ``state_dict`` returned (same config: task, robot, num_envs)."""
        self.backend.load_physics_state(state["physics"].cpu().numpy())
        for name, value in state["task"].items():
            setattr(self.task_state, name, value.clone().to(self.device))
        self.stack.load_state_dict({name: value.to(self.device) for name, value in state["frames"].items()})
        self.episodes.load_state_dict(state, self.device)
        self.joint_targets = state["target"].clone().to(self.device)
        self.last_action = state["last_action"].clone().to(self.device)
        self.starts.load_state_dict(state)
        self.aids.load_state_dict(state)
        self._needs_reset = bool(state["needs_reset"])
        self.checks.since = int(state["since_check"])  # the pool as saved covers the steps until the next check

    def aid(self, kind: type[AidT]) -> AidT | None:
        """The env's training aid of type ``kind`` (``roto.envs.aids``), or None."""
        return self.aids.find(kind)

    def aid_metrics(self) -> dict[str, torch.Tensor]:
        """The training aids' scalars ("train/<name>" -> () tensor on the env's device; reading one
        waits for the device); empty without aids."""
        return self.aids.metrics()

    @property
    def needs_reset(self) -> bool:
        """Whether ``reset`` must come before the next ``step``."""
        return self._needs_reset

    def restart_where(self, done: torch.Tensor, count: int) -> None:
        """Start new episodes in the ``count`` worlds where ``done`` (B,) is True: starts taken
        from the pool (drawn now where it runs short), frame stacks refilled with their first
        frames. For a caller that steps the worlds itself (``roto.envs.single_world``)."""
        self.starts.pool.ensure(count)
        self.stack.reset_where(self._reset_where(done), done)

    @property
    def nonfinite_resets(self) -> int:
        """Worlds reset so far because their physics went non-finite (reading it waits for the device)."""
        return int(self.episodes.nonfinite_resets)

    def hold_action(self) -> torch.Tensor:
        """(1, num_actions) float32 action whose joint targets are the default (cupped) pose."""
        idx = self.indices
        return target_to_action(idx.act_qpos.take(idx.default_qpos), idx.ctrl_lo, idx.ctrl_hi).to(torch.float32)

    @property
    def unwrapped(self) -> RotoEnv:
        """This env (Gymnasium-style accessor)."""
        return self

    def observation_frame(
        self, selected: Selected, target: torch.Tensor, last_action: torch.Tensor, task: torch.Tensor | None
    ) -> dict[str, torch.Tensor]:
        """The env's groups of one frame (``Observer.frame``)."""
        return self.observer.frame(selected, target, last_action, task)

    def task_state_frame(self, state: object = None, length: torch.Tensor | None = None) -> torch.Tensor | None:
        """The ``task`` group's frame of ``state`` (default: the env's task state) after ``length``
        (B,) steps (default: the episodes' lengths); None when the env returns no task group."""
        state = self.task_state if state is None else state
        return self.observer.task_frame(state, self.episodes.length if length is None else length)

    # ------------------------------------------------------------------ internals

    def _starts_ready_for(self, done: torch.Tensor) -> bool:
        """Make this step's resets available in the pool; whether any world finished (a host read)."""
        count = int(done.sum())
        if count:
            self.starts.pool.ensure(count)
        return count > 0

    def _periodic_check(self) -> None:
        """Every ``checks.every`` steps of a sync-free step: top the pool of starts up for the next
        ones and raise on a non-finite action since the last check (on a GPU the action check cannot
        stop the step it happens in without waiting for the device)."""
        if self.checks.sync_free:
            with deliberate_host_sync(self.device):
                self.starts.pool.ensure(self.checks.every * self.num_envs)
                self.checks.raise_on_nonfinite_actions()

    def _task_inputs(self, selected: Selected) -> TaskInputs:
        # views of the backend's state: read before the step's resets overwrite it
        contact = (selected.ball_force > self.config.tactile_threshold).any(dim=1)
        return TaskInputs(ball_pos=selected.ball_pos, ball_vel=selected.ball_vel, ball_contact=contact)

    def _reset_where(self, done: torch.Tensor) -> dict[str, torch.Tensor]:
        """Start new episodes in the worlds where ``done`` (B,) is True from the next pooled starts,
        in world order; returns a (B, dim) frame per group whose ``done`` rows are their first frames.
        Fixed shapes throughout: nothing is read back from the device."""
        start = self.starts.pool.take_where(done)
        rows = done[:, None]
        self.backend.set_state_where(done, start["qpos"], start.get("qvel", self._zero_qvel))
        self.task.reset(self.task_state, done)
        for name in self.aids.start_task_fields:  # the task state an aid's start was recorded in
            field = getattr(self.task_state, name)
            where = done.view(-1, *[1] * (field.dim() - 1))
            setattr(self.task_state, name, torch.where(where, start[f"task/{name}"].to(field.dtype), field))
        self.joint_targets = torch.where(rows, start["target"], self.joint_targets)
        self.last_action.masked_fill_(rows, 0.0)
        self.episodes.clear(done)
        return {name: start[f"frame/{name}"] for name in self.groups}

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

from roto.envs.action_checks import check_action_finite, check_action_layout
from roto.envs.aids.build import build_aids
from roto.envs.aids.protocol import AidHost, StepContext, TrainingAid
from roto.envs.capacity import warp_capacity
from roto.envs.config import EnvConfig
from roto.envs.control import action_to_target, smooth_target, target_to_action
from roto.envs.episode_book import EpisodeBook
from roto.envs.frames import observation_frame
from roto.envs.indices import SceneIndices
from roto.envs.observations import OBS_GROUPS, OBS_MODES, FrameStack, task_frame
from roto.envs.selections import Selected, Selections
from roto.envs.spaces import BoundedBox
from roto.envs.start_draw import draw_candidates, draw_starts, first_frame
from roto.envs.start_pool import StartPool, check_balls_start_clear
from roto.robots import get_robot
from roto.robots.spec import RobotSpec
from roto.sim.backend import Backend, make_backend
from roto.sim.host_sync import deliberate_host_sync, resolve_device
from roto.sim.scene import build_scene
from roto.tasks import get_task
from roto.tasks.base import TaskInputs

AidT = TypeVar("AidT", bound=TrainingAid)

DEVICE_CHECK_EVERY = 16
"""Steps between the host reads of a GPU env (pool of starts, action finiteness)."""


def backend_for(config: EnvConfig, model: mujoco.MjModel) -> Backend:
    """The physics backend ``config`` names for ``model``; Warp's fixed per-world contact and
    constraint buffers are roto's measured figures for the pair unless the config gives them."""
    capacity = {}
    if config.backend == "warp":
        nconmax, njmax = warp_capacity(config.robot, config.task)
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
    """B parallel worlds of one roto task on one robot (see ``roto.make``)."""

    metadata: ClassVar[dict[str, Any]] = {"autoreset_mode": gym.vector.AutoresetMode.SAME_STEP}

    def __init__(self, config: EnvConfig) -> None:
        config.check_available()
        self.config = config
        self.task = get_task(config.task)
        self.robot: RobotSpec = get_robot(config.robot)
        self.num_envs = config.num_envs
        self.device = resolve_device(config.device)
        wanted = set(OBS_MODES[config.obs_mode]) | set(config.extra_groups)
        self.groups = tuple(group for group in OBS_GROUPS if group in wanted)
        self.balls = self.task.balls(self.robot)
        self.model, self.layout = build_scene(self.robot, self.balls, config.touch)
        self.backend = backend_for(config, self.model)
        self._generator = torch.Generator(device=self.device)
        self._generator.manual_seed(config.seed)
        # the parts other code reads: the scene's index sets, each world's joint targets (B, n_act)
        # float64 and last action (B, n_act) float32 (the single-world step writes the last two in
        # place), the episodes' statistics (EpisodeBook) and the training aids
        self.indices = SceneIndices.from_layout(self.layout, self.robot, self.model, self.device, config.touch)
        self.num_actions = self.robot.num_actions
        self.task_state = self.task.init_state(self.robot, self.num_envs, self.device)
        self.stack = FrameStack(config.frame_stack)
        self.episodes = EpisodeBook.empty(self.num_envs, self.device)
        self.joint_targets = torch.zeros(self.num_envs, self.num_actions, dtype=torch.float64, device=self.device)
        self.last_action = torch.zeros(self.num_envs, self.num_actions, dtype=torch.float32, device=self.device)
        self._zero_qvel = torch.zeros(self.num_envs, self.model.nv, dtype=torch.float64, device=self.device)
        host = AidHost(config, self.task, self.task_state, self.robot, self.device, self.model, self._start_frame)
        self.aids: tuple[TrainingAid, ...] = build_aids(host)  # training only: none in an evaluation env
        self._start_task_fields = tuple(name for aid in self.aids for name in aid.start_task_fields())
        self._watching_aids = tuple(aid for aid in self.aids if aid.watches_steps)
        self._starts = StartPool(self._draw_starts, size=self.num_envs, device=self.device)
        self.selections = Selections(self.indices, self.device, taxels=config.touch == "taxels")
        # reading the device is free on the CPU and waits for a GPU. A sync-free step reads nothing:
        # resets run masked every step, and the pool of starts and the action check are read every
        # `check_every` steps, the pool holding enough starts for every world to reset on each of
        # them (tests switch this on for a CPU env to check it against the CPU path)
        self.sync_free_step = self.device.type != "cpu"
        self.check_every = DEVICE_CHECK_EVERY if self.sync_free_step else 1
        self._since_check = 0
        self._actions_finite = torch.ones((), dtype=torch.bool, device=self.device)
        self._needs_reset = True
        self.frame_sizes = self._frame_sizes()
        self.observation_space = gym.spaces.Dict(
            {
                name: gym.spaces.Box(-np.inf, np.inf, (config.frame_stack * size,), np.float32)
                for name, size in self.frame_sizes.items()
            }
        )
        self.action_space = BoundedBox(-1.0, 1.0, (self.num_actions,), np.float32)
        # a task whose balls start inside the hand is refused now, not after rounds of redrawing
        check_balls_start_clear(self._draw_candidates, self.robot.name, self.task.name, self.device)

    # ------------------------------------------------------------------ public API

    def reset(self, seed: int | None = None) -> tuple[dict[str, torch.Tensor], dict[str, Any]]:
        """Reset every world; returns (obs, info). ``seed`` re-seeds the reset noise."""
        if seed is not None:
            self._generator.manual_seed(int(seed))
        self._starts.clear()  # a reset, seeded or not, starts from freshly drawn starts
        with deliberate_host_sync(self.device):  # a reset draws starts, reading the pool as it goes
            self._starts.ensure(self.check_every * self.num_envs)
        self._since_check = 0
        frame = self._reset_where(torch.ones(self.num_envs, dtype=torch.bool, device=self.device))
        if self.sync_free_step:  # read only every check_every steps: cover every world ending on each of them
            with deliberate_host_sync(self.device):
                self._starts.ensure(self.check_every * self.num_envs)
        self.stack.reset(frame)
        for aid in self.aids:
            aid.on_reset()
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
        action = self._check_action(action)
        target = action_to_target(action.to(torch.float64), self.indices.ctrl_lo, self.indices.ctrl_hi)
        self.joint_targets = smooth_target(target, self.joint_targets, self.config.action_smoothing)
        self.last_action = action.to(torch.float32, copy=True)  # never alias the caller's tensor

        sim = self.backend.step(self.joint_targets)
        selected = self.selections.of(sim)
        diverged = sim.diverged.to(self.device)

        inputs = self._task_inputs(selected)
        result = self.task.step(self.task_state, inputs)
        reward = functools.reduce(operator.add, result.reward_terms.values()).masked_fill(diverged, 0.0)
        self.episodes.add(reward, result.reward_terms)
        terminated = result.terminated | diverged
        truncated = (self.episodes.length >= self.config.episode_steps) & ~terminated

        frame = self.observation_frame(selected, self.joint_targets, self.last_action, self.task_state_frame())
        self.stack.push(frame)
        obs = self.stack.observation()

        done = terminated | truncated
        if self._watching_aids:  # training aids fed by the headline metric, before the resets
            metric = self.task.metrics(self.task_state)[self.task.headline_metric]
            seen = StepContext(
                sim.qpos, sim.qvel, self.joint_targets, self.task_state, metric, self.episodes.length, done
            )
            for aid in self._watching_aids:
                aid.observe(seen)
        info: dict[str, Any] = {"reward_terms": result.reward_terms, "nonfinite": diverged}
        # a step without resets skips them, unless asking would wait for the device: then the reset
        # runs every step, masked (a world that did not finish is left as it was)
        any_done = True if self.sync_free_step else self._ensure_starts(done)
        if any_done:
            info["final_obs"] = obs
            info["_final_obs"] = done
            info["episode"] = self.episodes.info(truncated, self.task.metrics(self.task_state))
            info["_episode"] = done
            self.episodes.nonfinite_resets += diverged.sum()  # stays on the device until someone reads it
            self.stack.reset_where(self._reset_where(done), done)
            obs = self.stack.observation()
        self._since_check += 1
        if self._since_check == self.check_every:
            self._periodic_check()
        return obs, reward.to(torch.float32), terminated, truncated, info

    def close(self) -> None:
        """Release the backend's threads."""
        self.backend.close()

    def state_dict(self) -> dict[str, Any]:
        """Everything that decides the env's future: physics, task counters, frame stack, RNG, pooled starts.
        ``load_state_dict`` of it on an env built from the same config continues bit-identically (exact resume)."""
        return {
            "physics": torch.from_numpy(self.backend.physics_state()),
            "task": {f.name: getattr(self.task_state, f.name).clone() for f in dataclasses.fields(self.task_state)},
            "frames": self.stack.state_dict(),
            **self.episodes.state_dict(),
            "target": self.joint_targets.clone(),
            "last_action": self.last_action.clone(),
            "generator": self._generator.get_state(),
            "starts": self._starts.state_dict(),
            "needs_reset": self._needs_reset,
            "since_check": self._since_check,
            **{aid.state_key: aid.state_dict() for aid in self.aids if aid.state_key},
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
        self._generator.set_state(state["generator"].cpu())
        if "starts" in state:
            self._starts.load_state_dict(state["starts"], self.device)
        else:  # saved before episode starts were pooled: draw afresh
            self._starts.clear()
        for aid in self.aids:
            if aid.state_key in state:
                aid.load_state_dict(state[aid.state_key])
        self._needs_reset = bool(state["needs_reset"])
        if "starts" in state and "since_check" in state:  # the pool as saved covers the steps until the next
            self._since_check = int(state["since_check"])  # check, as it did in the env that saved it
        else:  # saved by an older roto: top the pool up now (the same draws, earlier, so not bit-identical
            self._since_check = 0  # where what a draw returns changes meanwhile, as a bank of recorded states)
            if not self._needs_reset:
                self._starts.ensure(self.check_every * self.num_envs)

    def aid(self, kind: type[AidT]) -> AidT | None:
        """The env's training aid of type ``kind`` (``roto.envs.aids``), or None."""
        return next((aid for aid in self.aids if isinstance(aid, kind)), None)

    def aid_metrics(self) -> dict[str, torch.Tensor]:
        """The training aids' scalars ("train/<name>" -> () tensor on the env's device; reading one
        waits for the device); empty without aids."""
        return {name: value for aid in self.aids for name, value in aid.metrics().items()}

    @property
    def needs_reset(self) -> bool:
        """Whether ``reset`` must come before the next ``step``."""
        return self._needs_reset

    def restart_where(self, done: torch.Tensor, count: int) -> None:
        """Start new episodes in the ``count`` worlds where ``done`` (B,) is True: starts taken
        from the pool (drawn now where it runs short), frame stacks refilled with their first
        frames. For a caller that steps the worlds itself (``roto.envs.single_world``)."""
        self._starts.ensure(count)
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

    # ------------------------------------------------------------------ internals

    def _frame_sizes(self) -> dict[str, int]:
        n_obs, n_act = len(self.robot.observed_joints), self.num_actions
        sizes = {
            "tactile": len(self.robot.tactile_links) + len(self.layout.taxel_sensor),
            "proprio": 2 * n_obs + 2 * n_act,
            "privileged": 6 * len(self.balls),
            "task": self.task.observation_size + 1,
        }
        return {group: sizes[group] for group in self.groups}

    def _check_action(self, action: Any) -> torch.Tensor:
        action = check_action_layout(action, (self.num_envs, self.num_actions), self.device)
        if self.sync_free_step:  # read every `check_every` steps (_periodic_check)
            self._actions_finite &= torch.isfinite(action).all()
        else:
            check_action_finite(action)
        return action

    def _ensure_starts(self, done: torch.Tensor) -> bool:
        """Make this step's resets available in the pool; whether any world finished (a host read)."""
        count = int(done.sum())
        if count:
            self._starts.ensure(count)
        return count > 0

    def _periodic_check(self) -> None:
        """Every ``check_every`` steps (each step on the CPU): top the pool of starts up for the next
        ``check_every`` steps and raise on a non-finite action since the last check (on a GPU the
        action check cannot stop the step it happens in without waiting for the device)."""
        self._since_check = 0
        if not self.sync_free_step:
            return
        with deliberate_host_sync(self.device):
            self._starts.ensure(self.check_every * self.num_envs)
            if not bool(self._actions_finite):
                self._actions_finite.fill_(True)
                raise ValueError(
                    f"an action had non-finite values (NaN or inf) in the last {self.check_every} steps; "
                    "actions must be finite (on a GPU they are checked every few steps, not before each one)"
                )

    def _task_inputs(self, selected: Selected) -> TaskInputs:
        # views of the backend's state: read before the step's resets overwrite it
        contact = (selected.ball_force > self.config.tactile_threshold).any(dim=1)
        return TaskInputs(ball_pos=selected.ball_pos, ball_vel=selected.ball_vel, ball_contact=contact)

    def observation_frame(
        self, selected: Selected, target: torch.Tensor, last_action: torch.Tensor, task: torch.Tensor | None
    ) -> dict[str, torch.Tensor]:
        """The env's groups of one frame (``roto.envs.frames.observation_frame``)."""
        idx = self.indices
        return observation_frame(self.groups, self.config, selected, idx.obs_lo, idx.obs_hi, target, last_action, task)

    def task_state_frame(self, state: object = None, length: torch.Tensor | None = None) -> torch.Tensor | None:
        """The ``task`` group's frame of ``state`` (default: the env's task state) after ``length``
        (B,) steps (default: the episodes' lengths); None when the env returns no task group."""
        if "task" not in self.groups:
            return None
        state = self.task_state if state is None else state
        length = self.episodes.length if length is None else length
        return task_frame(self.task.observation(state), length, self.config.episode_steps)

    def _reset_where(self, done: torch.Tensor) -> dict[str, torch.Tensor]:
        """Start new episodes in the worlds where ``done`` (B,) is True from the next pooled starts,
        in world order; returns a (B, dim) frame per group whose ``done`` rows are their first frames.
        Fixed shapes throughout: nothing is read back from the device."""
        start = self._starts.take_where(done)
        rows = done[:, None]
        self.backend.set_state_where(done, start["qpos"], start.get("qvel", self._zero_qvel))
        self.task.reset(self.task_state, done)
        for name in self._start_task_fields:  # the task state an aid's start was recorded in
            field = getattr(self.task_state, name)
            where = done.view(-1, *[1] * (field.dim() - 1))
            setattr(self.task_state, name, torch.where(where, start[f"task/{name}"].to(field.dtype), field))
        self.joint_targets = torch.where(rows, start["target"], self.joint_targets)
        self.last_action.masked_fill_(rows, 0.0)
        self.episodes.clear(done)
        return {name: start[f"frame/{name}"] for name in self.groups}

    def _draw_starts(self, n: int) -> dict[str, torch.Tensor]:
        """n episode starts: the task's own (``roto.envs.start_draw.draw_starts``), drawn through
        each training aid in turn (an aid may start some elsewhere)."""
        draw = functools.partial(draw_starts, self, generator=self._generator)
        for aid in self.aids:
            draw = functools.partial(aid.draw_starts, draw=draw, generator=self._generator)
        return draw(n)

    def _start_frame(
        self, qpos: torch.Tensor, qvel: torch.Tensor, target: torch.Tensor, task_rows: dict[str, torch.Tensor]
    ) -> dict[str, torch.Tensor]:
        """The first frame ("frame/<group>" rows) of starts an aid draws (``start_draw.first_frame``)."""
        return first_frame(self, qpos, qvel, target, task_rows)[0]

    def _draw_candidates(self, n: int, generator: torch.Generator | None = None) -> dict[str, torch.Tensor]:
        """n candidate starts (``roto.envs.start_draw.draw_candidates``), drawn from ``generator``
        (default: the env's)."""
        return draw_candidates(self, n, generator or self._generator)

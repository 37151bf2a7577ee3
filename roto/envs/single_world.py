"""The control step of a one-world CPU env with numpy glue: the fast path of the Gymnasium ``Env``.

``RotoEnv.step`` is written for B worlds on any device: some ninety small torch ops a step, each
costing microseconds of dispatch whatever the batch size, so with one world the ops, not the
physics, set the pace of ``gymnasium.make("roto/...")``. ``SingleWorldStep`` runs the same step
for a one-world env on the CPU backend in numpy: the task's own rule (written once for torch and
numpy, ``roto.tasks.arrays``) on numpy views of the task state and of the physics state, and
numpy for everything around it (action to joint targets, the physics call, observation frame and
stack, reward and episode sums, terminations). The observation formulas are the env's own
(``proprio_parts``), and episode ends go through the env's own reset. It reads and writes the
env's state, so ``RotoEnv.step``, ``reset`` and ``state_dict`` stay valid between fast steps,
and its trajectories are bit-identical to ``RotoEnv.step``'s, the reference
(tests/envs/test_single_world.py).
"""

from __future__ import annotations

import dataclasses
import functools
import operator
from typing import Any

import numpy as np
import torch

from roto.envs.columns import Columns
from roto.envs.observations import proprio_parts
from roto.envs.roto_env import RotoEnv
from roto.sim.mujoco_cpu import MujocoCpuBackend
from roto.tasks.base import TaskInputs

SingleStep = tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]
"""(obs (k·dim,) float32 per group, reward, terminated, truncated, info) of one world."""


def supports_single_world_step(env: RotoEnv) -> bool:
    """Whether ``SingleWorldStep`` can run ``env``: one world on the CPU backend, CPU tensors, binary
    touch, no ``task`` group (and each ball's centre and velocity evenly spaced in qpos and qvel, as
    MuJoCo lays out free joints)."""
    cpu = env.device.type == "cpu" and isinstance(env.backend, MujocoCpuBackend) and not env.checks.sync_free
    balls_as_views = env.indices.ball_pos.start is not None and env.indices.ball_vel.start is not None
    plain = env.config.touch == "binary" and "task" not in env.groups
    return cpu and env.num_envs == 1 and balls_as_views and plain


def _finite(x: np.ndarray) -> np.ndarray:
    """``x`` with NaN and inf set to 0, in place (``nan_to_num(nan=0, posinf=0, neginf=0)``)."""
    finite = np.isfinite(x)
    if not np.logical_and.reduce(finite, axis=None):
        np.copyto(x, 0.0, where=~finite)
    return x


def _all_finite(x: np.ndarray) -> bool:
    """Whether every value of ``x`` is finite (the ufunc reduction itself: ``ndarray.all`` goes
    through a Python wrapper that costs more than the check on a few dozen values)."""
    return bool(np.logical_and.reduce(np.isfinite(x), axis=None))


class _Reader:
    """Columns of a persistent numpy array: a view made once where they are evenly spaced, else a
    gather each time (the same selection as ``Columns.take``)."""

    def __init__(self, columns: Columns, source: np.ndarray) -> None:
        view = columns.take(torch.from_numpy(source))
        self._view = view.numpy() if np.shares_memory(view.numpy(), source) else None
        self._source = source
        self._index = columns.index.numpy()

    def read(self) -> np.ndarray:
        """The columns' current values."""
        return self._view if self._view is not None else self._source[..., self._index]


class _Views:
    """numpy views of torch tensors the env may replace between steps, one per named slot, made
    again only when the slot holds another tensor (``Tensor.numpy()`` costs a microsecond or two)."""

    def __init__(self) -> None:
        self._slots: dict[str, tuple[torch.Tensor, np.ndarray]] = {}

    def of(self, slot: str, tensor: torch.Tensor) -> np.ndarray:
        """A numpy array sharing ``tensor``'s memory."""
        cached = self._slots.get(slot)
        if cached is not None and cached[0] is tensor:
            return cached[1]
        view = tensor.numpy()
        self._slots[slot] = (tensor, view)
        return view


class SingleWorldStep:
    """``RotoEnv.step`` of a one-world CPU env, for a numpy action, with numpy results.

    ``step`` returns the Gymnasium single-env tuple: at the end of an episode the episode's last
    observation (the world is reset within the step, as ``RotoEnv.step`` does), ``info`` with the
    step's reward terms as floats and, at an episode's end, the episode statistics as Python scalars.
    """

    def __init__(self, env: RotoEnv) -> None:
        if not supports_single_world_step(env):
            raise ValueError(
                f"SingleWorldStep needs one world on the CPU backend with binary touch, got num_envs={env.num_envs}, "
                f"device={env.device}, backend={type(env.backend).__name__}, touch={env.config.touch!r}"
            )
        self.env = env
        idx, backend = env.indices, env.backend
        qpos, qvel, sensors = backend.qpos, backend.qvel, backend.sensordata
        now = sensors[:, -1]
        self._obs_qpos = _Reader(idx.obs_qpos, qpos)
        self._obs_qvel = _Reader(idx.obs_qvel, qvel)
        self._act_qpos = _Reader(idx.act_qpos, qpos)
        self._ball_force = _Reader(idx.ball_force, sensors)
        self._tactile_force = _Reader(idx.tactile_force, now)
        # ball centres and velocities are evenly spaced columns of the state: views, made once
        self._ball_pos, self._ball_vel = _Reader(idx.ball_pos, qpos).read(), _Reader(idx.ball_vel, qvel).read()
        self._task_fields = tuple(field.name for field in dataclasses.fields(env.task_state))
        get_fields = operator.attrgetter(*self._task_fields)  # one field: the value, not a 1-tuple
        self._task_tensors_of = get_fields if len(self._task_fields) > 1 else lambda state: (get_fields(state),)
        # the task state's tensors the views below share (none yet)
        self._task_tensors: tuple[torch.Tensor | None, ...] = (None,) * len(self._task_fields)
        self._task_views: dict[str, np.ndarray] = {}
        self._obs_lo, self._obs_hi = idx.obs_lo.numpy(), idx.obs_hi.numpy()
        self._ctrl_lo = idx.ctrl_lo.numpy()[None]
        self._ctrl_span = (idx.ctrl_hi - idx.ctrl_lo).numpy()[None]
        config = env.config
        self._alpha = config.action_smoothing
        self._episode_steps = config.episode_steps
        self._threshold = config.tactile_threshold
        self._num_actions = env.num_actions
        self._done = torch.ones(1, dtype=torch.bool)
        self._frame_sizes = env.frame_sizes
        self._views = _Views()

    def step(self, action: Any) -> SingleStep:
        """One control step from ``action`` (a float array of num_actions values)."""
        env = self.env
        array = np.asarray(action)
        unusual = array.dtype.kind != "f" or array.size != self._num_actions or not _all_finite(array)
        if env.needs_reset or unusual:
            return self._reference_step(array)  # raises the env's own error
        target, last_action = self._set_action(array.reshape(1, -1))
        diverged = bool(env.backend.step_array(target)[0])
        terms, terminated = self._task_step()
        reward = 0.0 if diverged else functools.reduce(operator.add, terms.values())
        length = self._views.of("length", env.episodes.length)
        length += 1
        self._views.of("return", env.episodes.ret)[0] += reward
        terminated = diverged or terminated
        truncated = not terminated and int(length[0]) >= self._episode_steps
        obs = self._push_frame(target, last_action)
        info: dict[str, Any] = {"reward_terms": terms}
        if terminated or truncated:
            info["episode"] = self._reset(truncated, diverged)
        return obs, float(np.float32(reward)), terminated, truncated, info

    def _set_action(self, row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The env's joint targets (1, n) float64 and last action (1, n) float32 for action ``row``."""
        env = self.env
        clamped = np.minimum(np.maximum(row.astype(np.float64), -1.0), 1.0)
        target = self._ctrl_lo + (clamped + 1.0) * 0.5 * self._ctrl_span
        if self._alpha != 1.0:
            target = self._alpha * target + (1.0 - self._alpha) * self._views.of("target", env.joint_targets)
        # written into the env's own tensors (a new tensor a step costs more than the copy)
        self._views.of("target", env.joint_targets)[...] = target
        last_action = self._views.of("last_action", env.last_action)
        last_action[...] = row
        return target, last_action

    def _task_step(self) -> tuple[dict[str, float], bool]:
        """The task's rule on numpy views of its state (written back in place): the reward terms
        as floats and whether the task ended the episode."""
        env = self.env
        state = env.task_state
        tensors = self._task_tensors_of(state)
        if not all(map(operator.is_, tensors, self._task_tensors)):  # the env replaced a state tensor
            self._task_tensors = tensors
            self._task_views = {name: t.numpy() for name, t in zip(self._task_fields, tensors, strict=True)}
        views = self._task_views
        numpy_state = type(state)(**views)
        contact = np.logical_or.reduce(self._ball_force.read() > self._threshold, axis=1)
        result = env.task.step(numpy_state, TaskInputs(self._ball_pos, self._ball_vel, contact))
        for name, view in views.items():
            value = getattr(numpy_state, name)
            if value is not view:
                view[...] = value
        terms = {}
        for name, value in result.reward_terms.items():
            terms[name] = term = float(value[0])
            if name in env.episodes.term_sums:
                self._views.of(f"sum/{name}", env.episodes.term_sums[name])[0] += term
            else:
                env.episodes.term_sums[name] = torch.from_numpy(value.copy())
        return terms, bool(result.terminated[0])

    def _push_frame(self, target: np.ndarray, last_action: np.ndarray) -> dict[str, np.ndarray]:
        """Push this step's frame onto the env's stack in place (the oldest frame out, this
        step's frame written straight into the newest slot); the observation (copies)."""
        stack = self.env.stack.frames
        obs = {}
        for name in self.env.groups:
            frames = self._views.of(f"stack/{name}", stack[name])
            dim = self._frame_sizes[name]
            frames[:, :-dim] = frames[:, dim:]
            self._write_frame(name, frames[:, -dim:], target, last_action)
            obs[name] = frames[0].copy()
        return obs

    def _write_frame(self, name: str, out: np.ndarray, target: np.ndarray, last_action: np.ndarray) -> None:
        """Group ``name``'s part of this step's observation frame into ``out`` (1, dim) float32, as
        ``RotoEnv._frame`` makes it (each value cast once from float64 to float32, as there)."""
        if name == "tactile":
            np.greater(self._tactile_force.read(), self._threshold, out=out)
        elif name == "proprio":
            parts = proprio_parts(
                self._obs_qpos.read(), self._obs_qvel.read(), self._obs_lo, self._obs_hi, target, self._act_qpos.read()
            )
            _finite(np.concatenate([*parts, last_action], axis=-1, out=out, casting="same_kind"))
        else:  # privileged: the balls' centres and velocities
            balls = np.concatenate([self._ball_pos, self._ball_vel], axis=-1).reshape(1, -1)
            np.copyto(out, balls, casting="same_kind")
            _finite(out)

    def _reset(self, truncated: bool, diverged: bool) -> dict[str, Any]:
        """Start the next episode with the env's own reset; the ended episode's statistics."""
        env = self.env
        ended = env.episodes.info(torch.tensor([truncated]), env.task.metrics(env.task_state))
        episode = {k: v.item() for k, v in ended.items()}
        if diverged:
            env.episodes.nonfinite_resets += 1
        env.restart_where(self._done, 1)
        return episode

    def _reference_step(self, array: np.ndarray) -> SingleStep:
        """``RotoEnv.step`` itself (errors raise from there)."""
        return single_world_result(*self.env.step(torch.as_tensor(array, device=self.env.device).reshape(1, -1)))


def single_world_result(
    obs: dict[str, torch.Tensor],
    reward: torch.Tensor,
    terminated: torch.Tensor,
    truncated: torch.Tensor,
    info: dict[str, Any],
) -> SingleStep:
    """A one-world ``RotoEnv.step`` result as the single-env tuple (the episode's last observation
    where it ended; reward terms and episode statistics as Python scalars)."""
    if "final_obs" in info:
        obs = info["final_obs"]
    out_info: dict[str, Any] = {"reward_terms": {k: v.item() for k, v in info["reward_terms"].items()}}
    if "episode" in info:
        out_info["episode"] = {k: v.item() for k, v in info["episode"].items()}
    return {k: v.numpy()[0] for k, v in obs.items()}, reward.item(), terminated.item(), truncated.item(), out_info

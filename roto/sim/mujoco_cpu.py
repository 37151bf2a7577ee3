"""CPU backend: B MuJoCo worlds stepped by ``mujoco.rollout`` in C, on ``threads`` threads.

The full physics state of every world lives in one float64 array ``(B, nstate)``. A control step
rolls all B worlds ``substeps`` steps, in chunks spread over the calling thread and persistent
helper threads (``RolloutThreads``; the GIL is released inside ``rollout``, no per-world Python),
after which the last substep's state becomes the new state. Warm-start accelerations are zeroed
for every world, as ``rollout`` does, which keeps results independent of how worlds are spread
over threads.
"""

from __future__ import annotations

import mujoco
import numpy as np
import torch

from roto.sim.backend import SimState
from roto.sim.memory import check_fits
from roto.sim.one_world import OneWorldStep
from roto.sim.rollout_threads import RolloutThreads

_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS.value
_SERIAL_SENSOR_STATES = 32
"""Fewer states than this get their one sensor step on the calling thread alone: for a handful of
states, waking a helper costs more than it saves (benchmarks/README.md)."""


def state_offsets(model: mujoco.MjModel) -> tuple[int, int]:
    """Offsets of qpos and qvel inside a ``mjSTATE_FULLPHYSICS`` vector."""
    time = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_TIME.value)
    qpos = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_QPOS.value)
    return time, time + qpos


class MujocoCpuBackend:
    """B worlds of ``model`` on the CPU, on ``threads`` threads (the calling thread and ``threads - 1`` helpers)."""

    def __init__(self, model: mujoco.MjModel, num_worlds: int, *, substeps: int, threads: int = 1) -> None:
        if threads < 1:
            raise ValueError(f"threads must be >= 1, got {threads}")
        check_fits(model, num_worlds, substeps)  # before any allocation
        self.model = model
        self.num_worlds = num_worlds
        self.substeps = substeps
        self.threads = threads
        self.device = torch.device("cpu")
        self._pool: RolloutThreads | None = RolloutThreads(model, threads)
        self._nstate = mujoco.mj_stateSize(model, _FULL)
        self._qpos0, self._qvel0 = state_offsets(model)
        self.state = np.zeros((num_worlds, self._nstate))
        data = mujoco.MjData(model)
        self._initial_state = np.zeros(self._nstate)  # the model's reference state, time 0
        mujoco.mj_getState(model, data, self._initial_state, _FULL)
        self.state[:] = self._initial_state
        self._ctrl = np.zeros((num_worlds, substeps, model.nu))
        self._out_state = np.zeros((num_worlds, substeps, self._nstate))
        self._out_sensor = np.zeros((num_worlds, substeps, model.nsensordata))
        self._time_lag = (substeps - 0.5) * model.opt.timestep
        # one world steps on a persistent MjData (bit-identical to rollout, a fraction of its
        # overhead); a step that raised a MuJoCo warning goes through rollout after all
        self._one_world = OneWorldStep(model, substeps) if num_worlds == 1 else None
        self._one_sensor_step = OneWorldStep(model, 1)  # sensors_at for a single state
        # the state arrays are only ever written in place, so tensors sharing their memory are
        # made once; a step hands them out again (only `diverged` is fresh each step)
        self._qpos_tensor = torch.from_numpy(self.qpos)
        self._qvel_tensor = torch.from_numpy(self.qvel)
        self._sensor_tensor = torch.from_numpy(self._out_sensor)

    @property
    def qpos(self) -> np.ndarray:
        """(B, nq) view of the current joint positions."""
        return self.state[:, self._qpos0 : self._qpos0 + self.model.nq]

    @property
    def qvel(self) -> np.ndarray:
        """(B, nv) view of the current joint velocities."""
        return self.state[:, self._qvel0 : self._qvel0 + self.model.nv]

    def step(self, ctrl: torch.Tensor) -> SimState:
        """Hold ``ctrl`` (B, nu) for ``substeps`` physics steps on every world, in C threads."""
        ctrl = ctrl.detach()
        if ctrl.dtype != torch.float64 or ctrl.device.type != "cpu":
            ctrl = ctrl.cpu().to(torch.float64)
        diverged = self.step_array(ctrl.numpy())
        return SimState(
            qpos=self._qpos_tensor,
            qvel=self._qvel_tensor,
            sensordata=self._sensor_tensor,
            diverged=torch.from_numpy(diverged),
        )

    def step_array(self, ctrl: np.ndarray) -> np.ndarray:
        """``step`` for a float64 array ``ctrl`` (B, nu); returns ``diverged`` (B,) bool, the new
        state being in ``state`` and the substeps' sensor values in ``sensordata``."""
        one_world = self._one_world
        if one_world is not None and one_world.step(self.state[0], ctrl[0], self._out_sensor[0]):
            return ~np.logical_and.reduce(np.isfinite(self.state), axis=1)
        self._ctrl[:] = ctrl[:, None, :]
        self._pool.run(self.state, self._ctrl, self._out_state, self._out_sensor, self.substeps)
        expected_time = self.state[:, 0] + self._time_lag
        self.state[:] = self._out_state[:, -1]
        # MuJoCo resets a world whose qpos/qvel/qacc go non-finite or huge (time restarts at 0),
        # and rollout stops stepping it; a clock that fell behind is how that shows.
        return (self.state[:, 0] < expected_time) | ~np.isfinite(self.state).all(axis=1)

    @property
    def sensordata(self) -> np.ndarray:
        """(B, substeps, nsensordata) view of the last step's sensor values of every substep."""
        return self._out_sensor

    def set_state(self, world_ids: torch.Tensor, qpos: torch.Tensor, qvel: torch.Tensor) -> None:
        """Overwrite worlds ``world_ids`` (n,) with ``qpos`` (n, nq), ``qvel`` (n, nv), time 0."""
        ids = world_ids.cpu().numpy()
        self.state[ids, 0] = 0.0
        self.state[ids, self._qpos0 : self._qpos0 + self.model.nq] = qpos.cpu().to(torch.float64).numpy()
        self.state[ids, self._qvel0 : self._qvel0 + self.model.nv] = qvel.cpu().to(torch.float64).numpy()

    def set_state_where(self, mask: torch.Tensor, qpos: torch.Tensor, qvel: torch.Tensor) -> None:
        """Overwrite the worlds where ``mask`` (B,) bool is True with their rows of ``qpos`` (B, nq)
        and ``qvel`` (B, nv), time 0 (the state lives on the host, so the mask is read here)."""
        ids = torch.nonzero(mask.cpu()).flatten()
        if len(ids):
            self.set_state(ids, qpos.cpu()[ids], qvel.cpu()[ids])

    def sensors_at(self, qpos: torch.Tensor, qvel: torch.Tensor, ctrl: torch.Tensor) -> torch.Tensor:
        """Sensordata (n, nsensordata) at the states ``qpos`` (n, nq), ``qvel`` (n, nv) under ``ctrl``
        (n, nu); no world changes.

        One throw-away physics step from each state computes them (sensors are evaluated on the
        state a step starts from); its resulting state is discarded. A single state (one world's
        reset) steps on a persistent ``MjData`` (``OneWorldStep``), a batch through ``rollout``.
        """
        n = len(qpos)
        state0 = np.repeat(self._initial_state[None], n, axis=0)
        state0[:, self._qpos0 : self._qpos0 + self.model.nq] = qpos.cpu().to(torch.float64).numpy()
        state0[:, self._qvel0 : self._qvel0 + self.model.nv] = qvel.cpu().to(torch.float64).numpy()
        sensors = np.zeros((n, 1, self.model.nsensordata))
        control = ctrl.cpu().to(torch.float64).numpy()
        if n == 1 and self._one_sensor_step.step(state0[0], control[0], sensors[0]):
            return torch.from_numpy(sensors[:, 0])
        self._pool.run(
            state0,
            np.ascontiguousarray(control[:, None, :]),
            np.zeros((n, 1, self._nstate)),
            sensors,
            nstep=1,
            threads=1 if n < _SERIAL_SENSOR_STATES else None,
        )
        return torch.from_numpy(sensors[:, 0])

    def physics_state(self) -> np.ndarray:
        """(B, nstate) float64 copy of every world's ``mjSTATE_FULLPHYSICS`` state."""
        return self.state.copy()

    def load_physics_state(self, state: np.ndarray) -> None:
        """Overwrite every world from a (B, nstate) ``mjSTATE_FULLPHYSICS`` array."""
        state = np.asarray(state)
        if state.shape != self.state.shape:
            raise ValueError(f"physics state has shape {state.shape}; this backend holds {self.state.shape}")
        self.state[:] = state

    def check_overflow(self) -> None:
        """Nothing to check: MuJoCo C grows its contact and constraint buffers as needed."""

    def close(self) -> None:
        """Stop the thread pool."""
        if self._pool is not None:
            self._pool.close()
            self._pool = None

"""Warp backend: B worlds of one model in one MuJoCo Warp ``Model``/``Data`` (``nworld = B``).

The same MJCF, robots and task code as the CPU backend; only the physics engine differs. Warp
computes in float32 (the CPU backend in float64), so results agree within a tolerance, not bit for
bit (docs/backends.md states the tolerances the parity tests use).

One control step is: write ``ctrl``, zero the warm-start accelerations (as ``mujoco.rollout`` does
on the CPU backend, so both backends start each control step's solver from the same guess), then
``substeps`` times ``mujoco_warp.step`` followed by a copy of that substep's sensordata into a
(B, substeps, nsensordata) buffer. On a CUDA device this whole sequence is captured once in a CUDA
graph and replayed, so a step launches one graph and never waits for the GPU. Torch tensors share
memory with the Warp arrays (``warp.to_torch``), so nothing is copied between the two.

Warp has no equivalent of MuJoCo's automatic reset of a diverged world, so a world whose qpos or
qvel turns non-finite or larger than MuJoCo's ``mjMAXVAL`` is flagged ``diverged`` (the env resets
it; other worlds are untouched). Contact and constraint capacities are fixed when the data is
made; Warp raises an overflow bit per world when one is exceeded, which :meth:`check_overflow`
turns into an error (checked after every step on Warp's CPU device; on a GPU every
``overflow_check_every`` steps and on demand, so the common step stays free of host
synchronisation).
"""

from __future__ import annotations

import functools
import os
import pathlib
import time

import mujoco
import numpy as np
import torch

from roto.sim.backend import SimState
from roto.sim.host_sync import deliberate_host_sync

MAX_VALUE = 1e10
"""MuJoCo's ``mjMAXVAL``: a |qpos| or |qvel| beyond it counts as diverged, as in MuJoCo C."""

_CAPACITY_FLAGS = {
    "NEFC": "constraint rows (njmax)",
    "NJMAX_NNZ": "constraint Jacobian non-zeros (njmax_nnz)",
    "BROADPHASE": "broadphase pairs (nconmax)",
    "NARROWPHASE": "contacts (nconmax)",
    "CCD": "convex-collision contacts (nccdmax)",
}
"""Warp overflow bits that mean a capacity was too small (results are then wrong); the solver's
iteration-limit bits are not errors and are ignored here."""


def warp_cache_dir() -> pathlib.Path:
    """Where compiled Warp kernels are cached: ``$ROTO_WARP_CACHE``, else ``.cache/warp`` in the
    source checkout roto runs from, else ``~/.cache/roto/warp``."""
    if os.environ.get("ROTO_WARP_CACHE"):
        return pathlib.Path(os.environ["ROTO_WARP_CACHE"])
    checkout = pathlib.Path(__file__).resolve().parents[2]
    if (checkout / "pyproject.toml").is_file() and os.access(checkout, os.W_OK):
        return checkout / ".cache" / "warp"
    return pathlib.Path.home() / ".cache" / "roto" / "warp"


def _import_warp():
    """Import warp and mujoco_warp, with roto's kernel cache and without per-module load messages."""
    try:
        import warp as wp
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(
            "backend 'warp' needs MuJoCo Warp; install roto's GPU extra: pip install -e '.[gpu]'"
        ) from error
    # takes effect when Warp initialises, i.e. unless something used Warp before roto did
    wp.config.kernel_cache_dir = str(warp_cache_dir())
    wp.config.log_level = 30  # warnings and errors, not one line per compiled module
    wp.init()
    import mujoco_warp as mjw

    return wp, mjw


@functools.cache
def _define_kernels(wp):
    """roto's own kernel, defined once per process: redefining it for every backend would mark its
    Warp module modified and reload it, under the feet of graphs already captured with it."""

    @wp.kernel
    def record_substep(
        sensordata: wp.array2d(dtype=wp.float32),
        substep: int,
        out: wp.array3d(dtype=wp.float32),
    ):
        world, i = wp.tid()
        out[world, substep, i] = sensordata[world, i]

    return record_substep


class MujocoWarpBackend:
    """B worlds of ``model`` in MuJoCo Warp on ``device`` (``cpu`` or ``cuda[:k]``).

    ``nconmax`` and ``njmax`` are the per-world contact and constraint-row capacities (see
    ``roto.sim.capacity`` for how roto sizes them per hand and task).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        num_worlds: int,
        *,
        substeps: int,
        device: str | torch.device = "cpu",
        nconmax: int,
        njmax: int,
        overflow_check_every: int | None = None,
    ) -> None:
        wp, mjw = _import_warp()
        self._wp, self._mjw = wp, mjw
        self.device = torch.device(device)
        if self.device.type == "cuda" and not wp.is_cuda_available():
            raise RuntimeError(
                f"device {str(device)!r} needs an NVIDIA GPU with a CUDA driver, and Warp finds none; "
                "use device='cpu' (Warp's CPU device, slow) or backend='cpu'"
            )
        self._wp_device = "cpu" if self.device.type == "cpu" else f"cuda:{self.device.index or 0}"
        self.model = model
        self.num_worlds = num_worlds
        self.substeps = substeps
        self.nconmax = nconmax
        self.njmax = njmax
        # reading the overflow bits waits for the device: every step on Warp's CPU device (free
        # there), every 100th on a GPU
        if overflow_check_every is None:
            overflow_check_every = 1 if self.device.type == "cpu" else 100
        self.overflow_check_every = overflow_check_every
        for part in ("HISTORY", "PLUGIN", "PLASTIC"):
            if mujoco.mj_stateSize(model, getattr(mujoco.mjtState, f"mjSTATE_{part}").value):
                raise ValueError(f"backend 'warp' does not carry mjSTATE_{part}, and this model has some")
        self._record_substep = _define_kernels(wp)
        with wp.ScopedDevice(self._wp_device):
            self._m = mjw.put_model(model)
            self._d = mjw.make_data(model, nworld=num_worlds, nconmax=nconmax, njmax=njmax)
            self._sensor_out = wp.zeros((num_worlds, substeps, model.nsensordata), dtype=wp.float32)
        d = self._d
        self._time = wp.to_torch(d.time)
        self._qpos = wp.to_torch(d.qpos)
        self._qvel = wp.to_torch(d.qvel)
        self._act = wp.to_torch(d.act)
        self._ctrl = wp.to_torch(d.ctrl)
        self._sensordata = wp.to_torch(d.sensordata)
        self._sensors = wp.to_torch(self._sensor_out)
        self._overflow = wp.to_torch(d.overflow)
        self._steps = 0
        self._step_graph = None
        self._forward_graph = None
        if self._wp_device.startswith("cuda"):
            self._capture_graphs()

    # ------------------------------------------------------------------ the captured sequences

    def _step_sequence(self) -> None:
        wp, mjw = self._wp, self._mjw
        self._d.qacc_warmstart.zero_()
        for k in range(self.substeps):
            mjw.step(self._m, self._d)
            wp.launch(
                self._record_substep,
                dim=(self.num_worlds, self.model.nsensordata),
                inputs=[self._d.sensordata, k],
                outputs=[self._sensor_out],
            )

    def _forward_sequence(self) -> None:
        self._d.qacc_warmstart.zero_()
        self._mjw.forward(self._m, self._d)

    def _capture_graphs(self) -> None:  # pragma: no cover - needs a GPU
        wp = self._wp
        # CUDA cannot capture on torch's default (legacy) stream: capture and replay on a stream of
        # our own, ordered against torch's current stream by events (``_run``), never by a host wait
        self._torch_stream = torch.cuda.Stream(self.device)
        self._stream = wp.stream_from_torch(self._torch_stream)
        saved = self.physics_state()  # a host copy: everything torch wrote so far is done
        with wp.ScopedDevice(self._wp_device), wp.ScopedStream(self._stream):
            # the first run compiles and loads every kernel; capture only the second
            self._step_sequence()
            self._forward_sequence()
            with wp.ScopedCapture() as capture:
                self._step_sequence()
            self._step_graph = capture.graph
            with wp.ScopedCapture() as capture:
                self._forward_sequence()
            self._forward_graph = capture.graph
        wp.synchronize_device(self._wp_device)  # once, while building: the uncaptured runs are done
        self.load_physics_state(saved)

    def _run(self, graph, sequence) -> None:
        wp = self._wp
        if graph is None:
            with wp.ScopedDevice(self._wp_device):
                sequence()
        else:  # pragma: no cover - needs a GPU
            current = torch.cuda.current_stream(self.device)
            self._torch_stream.wait_stream(current)  # the graph reads what torch wrote (ctrl, state)
            with wp.ScopedStream(self._stream):
                wp.capture_launch(graph)
            current.wait_stream(self._torch_stream)  # torch reads what the graph wrote

    # ------------------------------------------------------------------ Backend protocol

    def step(self, ctrl: torch.Tensor) -> SimState:
        """Hold ``ctrl`` (B, nu) for ``substeps`` physics steps on every world."""
        self._ctrl.copy_(ctrl)
        self._run(self._step_graph, self._step_sequence)
        self._steps += 1
        if self.overflow_check_every and self._steps % self.overflow_check_every == 0:
            with deliberate_host_sync(self.device):
                self.check_overflow()
        # NaN and inf both fail "<= MAX_VALUE", so one comparison covers non-finite values too
        diverged = ~((self._qpos.abs() <= MAX_VALUE).all(dim=1) & (self._qvel.abs() <= MAX_VALUE).all(dim=1))
        return SimState(qpos=self._qpos, qvel=self._qvel, sensordata=self._sensors, diverged=diverged)

    def set_state(self, world_ids: torch.Tensor, qpos: torch.Tensor, qvel: torch.Tensor) -> None:
        """Overwrite worlds ``world_ids`` (n,) with ``qpos`` (n, nq), ``qvel`` (n, nv), time 0."""
        ids = world_ids.to(self.device)
        if len(ids) == 0:
            return
        self._time[ids] = 0.0
        self._qpos[ids] = qpos.to(self.device, torch.float32)
        self._qvel[ids] = qvel.to(self.device, torch.float32)
        self._act[ids] = 0.0

    def set_state_where(self, mask: torch.Tensor, qpos: torch.Tensor, qvel: torch.Tensor) -> None:
        """Overwrite the worlds where ``mask`` (B,) bool is True with their rows of ``qpos`` (B, nq)
        and ``qvel`` (B, nv), time 0; fixed shapes, so nothing is read back from the device."""
        rows = mask.to(self.device)[:, None]
        self._time.masked_fill_(mask, 0.0)
        self._qpos.copy_(torch.where(rows, qpos.to(self.device, torch.float32), self._qpos))
        self._qvel.copy_(torch.where(rows, qvel.to(self.device, torch.float32), self._qvel))
        self._act.masked_fill_(rows, 0.0)

    def sensors_at(self, qpos: torch.Tensor, qvel: torch.Tensor, ctrl: torch.Tensor) -> torch.Tensor:
        """Sensordata (n, nsensordata) at the states ``qpos`` (n, nq), ``qvel`` (n, nv) under ``ctrl``
        (n, nu); no world changes.

        Up to B states at a time are written into the first worlds, whose state is kept aside, and
        one ``forward`` of every world (the captured graph on a GPU) evaluates the sensors; then the
        kept state goes back (forward changes no state, so the other worlds are unaffected).
        """
        parts = (self._time, self._qpos, self._qvel, self._act, self._ctrl)
        chunks = []
        for first in range(0, len(qpos), self.num_worlds):
            rows = slice(0, min(self.num_worlds, len(qpos) - first))
            kept = [part[rows].clone() for part in parts]
            chunk = slice(first, first + rows.stop)
            self._time[rows] = 0.0
            self._qpos[rows] = qpos[chunk].to(self.device, torch.float32)
            self._qvel[rows] = qvel[chunk].to(self.device, torch.float32)
            self._act[rows] = 0.0
            self._ctrl[rows] = ctrl[chunk].to(self.device, torch.float32)
            self._run(self._forward_graph, self._forward_sequence)
            chunks.append(self._sensordata[rows].clone())
            for part, value in zip(parts, kept, strict=True):
                part[rows] = value
        if not chunks:
            return torch.zeros((0, self.model.nsensordata), dtype=torch.float32, device=self.device)
        return torch.cat(chunks)

    def physics_state(self) -> np.ndarray:
        """(B, nstate) float64 host copy of every world's ``mjSTATE_FULLPHYSICS`` state."""
        parts = [self._time[:, None], self._qpos, self._qvel, self._act]
        return torch.cat([p.to(torch.float64) for p in parts], dim=1).cpu().numpy()

    def load_physics_state(self, state: np.ndarray) -> None:
        """Overwrite every world from a (B, nstate) ``mjSTATE_FULLPHYSICS`` array."""
        m = self.model
        tensor = torch.as_tensor(np.asarray(state), device=self.device).to(torch.float32)
        expected = (self.num_worlds, 1 + m.nq + m.nv + m.na)
        if tuple(tensor.shape) != expected:
            raise ValueError(f"physics state has shape {tuple(tensor.shape)}; this backend holds {expected}")
        self._time.copy_(tensor[:, 0])
        self._qpos.copy_(tensor[:, 1 : 1 + m.nq])
        self._qvel.copy_(tensor[:, 1 + m.nq : 1 + m.nq + m.nv])
        self._act.copy_(tensor[:, 1 + m.nq + m.nv :])

    def check_overflow(self) -> None:
        """Raise if any world has exceeded a contact or constraint capacity since it was made."""
        bits = _or_all(self._overflow)
        flags = self._mjw.OverflowType
        exceeded = [what for name, what in _CAPACITY_FLAGS.items() if bits & int(getattr(flags, name))]
        if exceeded:
            raise RuntimeError(
                f"MuJoCo Warp ran out of capacity for {', '.join(exceeded)} (nconmax={self.nconmax}, "
                f"njmax={self.njmax} per world); contacts were dropped, so results are wrong. "
                "Raise the capacity (roto.sim.capacity) and run again."
            )

    def bare_physics_steps_per_s(self, control_steps: int) -> float:
        """Aggregate physics steps/s of plain ``mujoco_warp.step`` on this model and device.

        Runs on a separate ``Data`` started from a copy of every world's current state and ctrl
        (this backend's worlds are untouched), ``substeps`` steps per control step, captured in a
        CUDA graph on a GPU like the env's own step, for ``control_steps`` control steps.
        """
        wp, mjw = self._wp, self._mjw
        m = self.model
        with wp.ScopedDevice(self._wp_device):
            d = mjw.make_data(m, nworld=self.num_worlds, nconmax=self.nconmax, njmax=self.njmax)
            for name in ("time", "qpos", "qvel", "act", "ctrl"):
                wp.to_torch(getattr(d, name)).copy_(wp.to_torch(getattr(self._d, name)))

            def sequence() -> None:
                for _ in range(self.substeps):
                    mjw.step(self._m, d)

            if self._step_graph is not None:  # pragma: no cover - needs a GPU
                torch.cuda.synchronize(self.device)  # the copies above ran on torch's stream
            sequence()  # compile / load
            graph = None
            if self._step_graph is not None:  # pragma: no cover - needs a GPU
                with wp.ScopedStream(self._stream), wp.ScopedCapture() as capture:
                    sequence()
                graph = capture.graph
            wp.synchronize()
            start = time.perf_counter()
            for _ in range(control_steps):
                if graph is None:
                    sequence()
                else:  # pragma: no cover - needs a GPU
                    wp.capture_launch(graph, stream=self._stream)
            wp.synchronize()
            elapsed = time.perf_counter() - start
        return self.num_worlds * self.substeps * control_steps / elapsed

    def close(self) -> None:
        """Drop the captured graphs (the device arrays go with the backend)."""
        self._step_graph = self._forward_graph = None


def _or_all(bits: torch.Tensor) -> int:
    """Bitwise OR of an int tensor (one host read)."""
    values = bits.cpu().numpy()
    return int(np.bitwise_or.reduce(values)) if values.size else 0

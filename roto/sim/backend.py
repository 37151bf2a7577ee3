"""What the env needs from a physics backend; backends never know which task runs on them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
import torch


@dataclass(frozen=True)
class SimState:
    """Batched simulator output after one control step, as torch tensors on the env's device.

    Attributes:
        qpos: (B, nq) joint positions after the last substep.
        qvel: (B, nv) joint velocities after the last substep.
        sensordata: (B, substeps, nsensordata) sensor values of every substep (contact sensors are
            evaluated at the start of each substep's integration, i.e. on the state it stepped from).
        diverged: (B,) bool, worlds whose physics went non-finite during the step (their state is
            not meaningful and must be reset).
    """

    qpos: torch.Tensor
    qvel: torch.Tensor
    sensordata: torch.Tensor
    diverged: torch.Tensor


class Backend(Protocol):
    """A batch of B worlds of one MuJoCo model, stepped together."""

    num_worlds: int
    substeps: int
    device: torch.device

    def step(self, ctrl: torch.Tensor) -> SimState:
        """Hold ``ctrl`` (B, nu) for ``substeps`` physics steps on every world."""
        ...

    def set_state(self, world_ids: torch.Tensor, qpos: torch.Tensor, qvel: torch.Tensor) -> None:
        """Overwrite the given worlds' state (n,) with ``qpos`` (n, nq), ``qvel`` (n, nv), time 0."""
        ...

    def set_state_where(self, mask: torch.Tensor, qpos: torch.Tensor, qvel: torch.Tensor) -> None:
        """Overwrite the worlds where ``mask`` (B,) bool is True with their rows of ``qpos`` (B, nq)
        and ``qvel`` (B, nv), time 0; the other rows are ignored."""
        ...

    def sensors_at(self, qpos: torch.Tensor, qvel: torch.Tensor, ctrl: torch.Tensor) -> torch.Tensor:
        """Sensordata (n, nsensordata) at the states ``qpos`` (n, nq), ``qvel`` (n, nv) under ``ctrl``
        (n, nu), evaluated as a step from them would; no world changes."""
        ...

    def physics_state(self) -> np.ndarray:
        """(B, nstate) float64 host copy of every world's ``mjSTATE_FULLPHYSICS`` state."""
        ...

    def load_physics_state(self, state: np.ndarray) -> None:
        """Overwrite every world from a (B, nstate) ``mjSTATE_FULLPHYSICS`` array."""
        ...

    def check_overflow(self) -> None:
        """Raise if a fixed contact or constraint capacity was exceeded (no-op where none is fixed)."""
        ...

    def close(self) -> None:
        """Release threads and buffers."""
        ...


BACKENDS = ("cpu", "warp")
"""Physics backends: ``cpu`` (MuJoCo C in threads) and ``warp`` (MuJoCo Warp, GPU or Warp's CPU)."""

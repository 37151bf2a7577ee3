"""What the env needs from a physics backend; backends never know which task runs on them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

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

    def set_state(
        self, world_ids: torch.Tensor, qpos: torch.Tensor, qvel: torch.Tensor, ctrl: torch.Tensor
    ) -> torch.Tensor:
        """Overwrite the given worlds' state; return their sensordata (len(ids), nsensordata) at it."""
        ...

    def close(self) -> None:
        """Release threads and buffers."""
        ...

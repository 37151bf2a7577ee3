"""The columns of the physics state that the task and the observations read, per step.

``Selections.of`` selects them from a backend's step output. A backend that hands out the same
tensors every step (the CPU one: views of arrays it writes in place) gets the selections that are
views made once, as they read each step's values; only those that are copies (a gather of
irregular columns) are made again each step. ``Selections.select`` is the plain path, used for
states that are not the backend's (episode starts) and as the reference of the cached one
(tests/envs/test_selections.py).
"""

from __future__ import annotations

from typing import NamedTuple

import torch

from roto.envs.indices import SceneIndices
from roto.sim.backend import SimState


class Selected(NamedTuple):
    """The columns of a batch of n physics states that the task and the observations read."""

    obs_qpos: torch.Tensor  # (n, n_obs) observed joint positions
    obs_qvel: torch.Tensor  # (n, n_obs) their velocities
    act_qpos: torch.Tensor  # (n, n_act) actuated joint positions
    ball_pos: torch.Tensor  # (n, n_ball, 3) ball centres
    ball_vel: torch.Tensor  # (n, n_ball, 3) ball linear velocities
    ball_force: torch.Tensor  # (n, substeps, n_ball) ball-hand normal force of every substep
    tactile_force: torch.Tensor  # last substep: (n, n_links) normal force, or (n, n_links, 3) net force (force touch)
    taxel_force: torch.Tensor | None = None  # last substep: (n, n_taxels) each taxel's normal force (taxel touch)


def is_view_of(tensor: torch.Tensor, bases: tuple[torch.Tensor, ...]) -> bool:
    """Whether ``tensor`` shares its memory with one of ``bases`` (a view, not a copy)."""
    ptr = tensor.untyped_storage().data_ptr()
    return any(ptr == base.untyped_storage().data_ptr() for base in bases)


class Selections:
    """The env's column selections (``SceneIndices``) of qpos, qvel and sensordata, on ``device``."""

    def __init__(self, idx: SceneIndices, device: torch.device, taxels: bool) -> None:
        self.device = device
        # (columns, source) per field of Selected; sources: 0 qpos, 1 qvel, 2 sensors, 3 last substep's
        self.table = (
            (idx.obs_qpos, 0),
            (idx.obs_qvel, 1),
            (idx.act_qpos, 0),
            (idx.ball_pos, 0),
            (idx.ball_vel, 1),
            (idx.ball_force, 2),
            (idx.tactile_force, 3),
        ) + (((idx.taxels, 3),) if taxels else ())
        self.cache: tuple | None = None
        """(qpos, qvel, sensordata the views were made of, their Selected, indices of the copies)"""

    def select(self, qpos: torch.Tensor, qvel: torch.Tensor, sensors: torch.Tensor) -> Selected:
        """The columns of physics states ``qpos`` (n, nq), ``qvel`` (n, nv) and ``sensors``
        (n, substeps, nsensordata), the last substep's being the current ones."""
        sources = (qpos, qvel, sensors, sensors[:, -1])
        return Selected(*(columns.take(sources[k]) for columns, k in self.table))

    def of(self, sim: SimState) -> Selected:
        """``select`` of a step's physics state, the views made once where the backend allows."""
        cached = self.cache
        if cached is not None and cached[0] is sim.qpos and cached[1] is sim.qvel and cached[2] is sim.sensordata:
            selected, copies = cached[3], cached[4]
            if not copies:
                return selected
            sources = (sim.qpos, sim.qvel, sim.sensordata, sim.sensordata[:, -1])
            values = list(selected)
            for i in copies:
                columns, k = self.table[i]
                values[i] = columns.take(sources[k])
            return Selected(*values)
        f64 = torch.float64
        qpos = sim.qpos.to(self.device, f64)
        qvel = sim.qvel.to(self.device, f64)
        sensors = sim.sensordata.to(self.device, f64)
        selected = self.select(qpos, qvel, sensors)
        if qpos is sim.qpos and qvel is sim.qvel and sensors is sim.sensordata:  # no conversion copied them
            bases = (qpos, qvel, sensors)
            copies = tuple(i for i in range(len(self.table)) if not is_view_of(selected[i], bases))
            self.cache = (sim.qpos, sim.qvel, sim.sensordata, selected, copies)
        return selected

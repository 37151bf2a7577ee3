"""Recorded states that training episodes may start from (reference-state initialisation).

A bank holds states recorded in one hand's scene, e.g. by the Baoding reference controller just
before its swaps (``roto demo --task baoding --preswap_out``): each state's physics (qpos and qvel),
the joint targets held then, and the task state fields the file carries (Baoding: ``swapped`` and
``latched``). The env draws a share of its episode starts from the bank (``EnvConfig.replay_share``)
instead of the task's own starts; evaluation never does.
"""

from __future__ import annotations

import dataclasses
import pathlib
from dataclasses import dataclass

import mujoco
import numpy as np
import torch

from roto.sim.mujoco_cpu import state_offsets


@dataclass(frozen=True)
class ReplayBank:
    """n recorded states: qpos (n, nq), qvel (n, nv), target (n, n_act) and task fields name -> (n, ...)."""

    qpos: torch.Tensor
    qvel: torch.Tensor
    target: torch.Tensor
    task: dict[str, torch.Tensor]

    def __len__(self) -> int:
        return len(self.qpos)

    def to(self, device: torch.device) -> ReplayBank:
        """The bank on ``device``."""
        return ReplayBank(
            self.qpos.to(device),
            self.qvel.to(device),
            self.target.to(device),
            {name: value.to(device) for name, value in self.task.items()},
        )

    def state_dict(self) -> dict[str, object]:
        """Copies of the bank's tensors (saved with the env, so a resume draws from the same states)."""
        return {
            "qpos": self.qpos.clone(),
            "qvel": self.qvel.clone(),
            "target": self.target.clone(),
            "task": dict(self.task),
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, object], device: torch.device) -> ReplayBank:
        """Inverse of ``state_dict``."""
        return cls(state["qpos"], state["qvel"], state["target"], state["task"]).to(device)


def load_replay_bank(path: str, model: mujoco.MjModel, robot: str, task_state: object, num_actions: int) -> ReplayBank:
    """The states of ``path`` (arrays ``physics`` (n, nstate) ``mjSTATE_FULLPHYSICS``, ``target``
    (n, n_act), ``robot`` and task state fields) for ``model`` of ``robot``; task fields are the
    arrays named like a field of ``task_state``.

    Raises:
        ValueError naming the file when it is missing, of another robot, of another model or holds
        no state.
    """
    if not pathlib.Path(path).is_file():  # checked here, where it is read: a run's config stays loadable without it
        raise ValueError(
            f"replay_starts {str(path)!r} is not a file (a relative path is read from the current directory, "
            f"{str(pathlib.Path.cwd())!r}; the packaged configs' banks are relative to the repository root)"
        )
    with np.load(path, allow_pickle=False) as saved:
        arrays = {name: saved[name] for name in saved.files}
    if "robot" in arrays and str(arrays["robot"]) != robot:
        raise ValueError(f"replay_starts {path!r}: states of robot {str(arrays['robot'])!r}, not {robot!r}")
    physics, target = arrays.get("physics"), arrays.get("target")
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS.value)
    if physics is None or target is None or physics.ndim != 2 or len(physics) == 0:
        raise ValueError(f"replay_starts {path!r}: needs non-empty arrays 'physics' (n, nstate) and 'target'")
    if physics.shape[1] != nstate or target.shape != (len(physics), num_actions):
        raise ValueError(
            f"replay_starts {path!r}: states of {physics.shape[1]} values and targets of shape {target.shape} do not "
            f"fit this scene ({nstate} values, {num_actions} actions)"
        )
    qpos0, qvel0 = state_offsets(model)
    fields = {f.name for f in dataclasses.fields(task_state)}
    return ReplayBank(
        qpos=torch.from_numpy(physics[:, qpos0 : qpos0 + model.nq].copy()),
        qvel=torch.from_numpy(physics[:, qvel0 : qvel0 + model.nv].copy()),
        target=torch.from_numpy(target.astype(np.float64)),
        task={name: torch.from_numpy(value.copy()) for name, value in arrays.items() if name in fields},
    )

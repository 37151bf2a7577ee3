"""The training-aid protocol: what every aid implements, and what an env shows it.

A training aid changes how training envs start or pay their episodes (replayed starts, recorded
own events, a tolerance curriculum, round-only swaps); evaluation envs never carry one
(``EnvConfig.without_training_aids``). ``RotoEnv`` builds the aids its config asks for
(``roto.envs.aids.build_aids``) and loops over them as PPO loops over its auxiliary losses: starts
are drawn through them, every control step is shown to each, a full reset is announced, and their
state is saved with the env's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import mujoco
import torch

from roto.envs.config import EnvConfig
from roto.robots.spec import RobotSpec
from roto.tasks.base import Task

StartRows = dict[str, torch.Tensor]
"""n episode starts: "qpos" (n, nq), "qvel" (n, nv), "target" (n, n_act), "frame/<group>" (n, dim),
and optionally "task/<field>" rows (the task state a start begins in) and "replayed" (n,) bool."""

DrawStarts = Callable[[int], StartRows]
"""n valid episode starts."""


@dataclass(frozen=True)
class AidHost:
    """What an aid may know of its env when it is built: the config (``num_envs`` ...), the task and
    its state, the robot record, the device, the compiled scene and how the env makes a start's
    first frame."""

    config: EnvConfig
    task: Task
    task_state: Any
    robot: RobotSpec
    device: torch.device
    model: mujoco.MjModel
    first_frame: Callable[[torch.Tensor, torch.Tensor, torch.Tensor, dict[str, torch.Tensor]], StartRows]
    """(qpos (n, nq), qvel (n, nv), target (n, n_act), task rows) -> the starts' "frame/<group>" rows."""


@dataclass(frozen=True)
class StepContext:
    """One control step of every world as the aids see it: after the task's counters, before the
    worlds that finished are reset.

    Attributes:
        qpos, qvel: (B, nq), (B, nv) the physics after the step.
        target: (B, n_act) the joint targets held during it.
        task_state: the task's state (read only: an aid changes a task parameter through
            ``Task.set_parameter``).
        metric: (B,) the task's headline metric so far this episode.
        length: (B,) int64 control steps of each episode so far.
        done: (B,) bool, episodes that end now.
    """

    qpos: torch.Tensor
    qvel: torch.Tensor
    target: torch.Tensor
    task_state: Any
    metric: torch.Tensor
    length: torch.Tensor
    done: torch.Tensor


class TrainingAid:
    """Every hook of the protocol, each doing nothing: an aid overrides the ones it needs.

    ``state_key`` names its state in the env's ``state_dict``; ``watches_steps`` says whether it
    needs ``observe`` (the env then computes the headline metric each step)."""

    state_key: ClassVar[str] = ""
    watches_steps: ClassVar[bool] = False

    def draw_starts(self, n: int, draw: DrawStarts, generator: torch.Generator) -> StartRows:
        """n starts: by default ``draw``'s (the task's own, or the previous aid's)."""
        return draw(n)

    def start_task_fields(self) -> tuple[str, ...]:
        """Task state fields this aid's starts carry ("task/<field>" rows) for the env to restore."""
        return ()

    def observe(self, step: StepContext) -> None:
        """One control step of every world (only when ``watches_steps``)."""

    def on_reset(self) -> None:
        """Every world starts a new episode (``RotoEnv.reset``)."""

    def metrics(self) -> dict[str, torch.Tensor]:
        """Scalars to log once per update ("train/<name>" -> () tensor on the env's device)."""
        return {}

    def state_dict(self) -> dict[str, Any]:
        """Everything that decides the aid's future (saved with the env: an exact resume)."""
        return {}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what ``state_dict`` returned."""

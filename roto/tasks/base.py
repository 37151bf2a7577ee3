"""The task protocol: what every task provides, written once for every robot.

A task sees the robot only as data (``RobotSpec``) and the simulation only as batched arrays
(``TaskInputs``); it never names a robot and never touches a backend. Its ``step`` runs on torch
tensors in every batched env and on numpy arrays in the one-world Gymnasium step, with the same
code: it uses operators, indexing, ``sum``/``any``/``all(axis=...)`` and ``roto.tasks.arrays``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Protocol

import torch

from roto.robots.spec import RobotSpec
from roto.sim.scene import BallSpec

PALM_DROP_LIMIT = 0.2
"""A ball more than this far below the palm centre (m) ends the episode (docs/spec.md §5, §6)."""


@dataclass(frozen=True)
class TaskInputs:
    """Per-step batched quantities a task reads (task frame: palm centre at the origin, z up);
    torch tensors, or numpy arrays in the one-world step.

    Attributes:
        ball_pos: (B, n_ball, 3) ball centres, m.
        ball_vel: (B, n_ball, 3) ball linear velocities, m/s.
        ball_contact: (B, n_ball) bool, the ball touched the hand during the control step.
    """

    ball_pos: torch.Tensor
    ball_vel: torch.Tensor
    ball_contact: torch.Tensor


@dataclass(frozen=True)
class StepResult:
    """What a task returns each step.

    Attributes:
        reward_terms: name -> (B,) reward term, already scaled; the reward is their sum.
        terminated: (B,) bool, failure condition reached.
    """

    reward_terms: dict[str, torch.Tensor]
    terminated: torch.Tensor


@dataclass(frozen=True)
class Marker:
    """A point a task wants drawn in pictures and videos (not part of the physics).

    Attributes:
        pos: (B, 3) position per world, task frame, m.
        radius: sphere radius, m.
        rgba: colour.
    """

    pos: torch.Tensor
    radius: float
    rgba: tuple[float, float, float, float]


class Task(Protocol):
    """A robot-agnostic task."""

    name: str
    display_name: str
    version: int
    """The Gymnasium id's version, bumped whenever dynamics, rewards, observations or terminations change."""
    metric_names: tuple[str, ...]
    headline_metric: str
    """The metric results tables rank agents by (one of ``metric_names``, per 10 s episode)."""
    reference_name: str
    """What ``reference`` is (a scripted policy, a controller)."""
    reference: Mapping[str, float]
    """{robot: the reference's ``headline_metric``}, measured (docs/robots.md): what a learned agent
    is set beside."""
    observation_size: int
    """Features per world of ``observation`` (the ``task`` observation group holds one more: time left)."""
    selection_metric: str | None
    """The evaluation measure ``best.pt`` is chosen by and reports lead with (one of
    ``metric_names`` or ``path_metric_names``), the return breaking ties; None: the return alone."""
    path_metric_names: tuple[str, ...]
    """Episode measures read from the balls' whole path and the episode's metrics (``path_metrics``);
    evaluation reports them, training never sees them. May be empty."""
    parameters: Mapping[str, float]
    """{name: the benchmark's value} of the task parameters a training aid may change
    (``set_parameter``); may be empty."""

    def balls(self, robot: RobotSpec) -> tuple[BallSpec, ...]:
        """The free objects this task puts in the scene for ``robot``."""
        ...

    def init_state(self, robot: RobotSpec, num_envs: int, device: torch.device) -> object:
        """Fresh per-env task state (counters, latches)."""
        ...

    def reset(self, state: object, mask: torch.Tensor) -> None:
        """Clear the task state of the worlds where ``mask`` (B,) bool is True, for a new episode."""
        ...

    def initial_ball_positions(self, state: object, n: int, generator: torch.Generator) -> torch.Tensor:
        """Ball positions (n, n_ball, 3) that start n new episodes, drawn from ``generator``."""
        ...

    def step(self, state: object, inputs: TaskInputs) -> StepResult:
        """Advance counters by one control step; return reward terms and terminations (arrays of
        the inputs' kind; ``state``'s arrays are of that kind too, updated in place or replaced)."""
        ...

    def metrics(self, state: object) -> dict[str, torch.Tensor]:
        """Episode metrics so far, name -> (B,) float."""
        ...

    def observation(self, state: object) -> torch.Tensor:
        """(B, observation_size) float features of the task state a critic may read (never the policy)."""
        ...

    def markers(self, state: object) -> list[Marker]:
        """What pictures and videos should draw besides the scene (e.g. targets); may be empty."""
        ...

    def path_metrics(self, ball_path: torch.Tensor, metrics: Mapping[str, float]) -> dict[str, float]:
        """``path_metric_names`` of one episode from its balls' centres ``ball_path`` (T, n_ball, 3)
        and its ``metric_names`` at its end (``metrics``)."""
        ...

    def set_parameter(self, state: object, name: str, value: float | torch.Tensor) -> None:
        """Set task parameter ``name`` (one of ``parameters``) of every world in ``state`` to
        ``value`` (a float or a () tensor on the state's device), in place, without reading the
        device. Raises ValueError naming the valid parameters for any other name."""
        ...

    def derived_metrics(self, episode: Mapping[str, float]) -> dict[str, float]:
        """Those ``path_metric_names`` of one episode that follow from its other measures alone
        (``episode``: its metrics and path metrics at its end), for which ``path_metrics`` uses this
        too; a result written before such a measure existed recomputes it from its stored episodes.
        Empty where the given measures do not include what one needs."""
        ...

    def path_kind(self, means: Mapping[str, float]) -> str | None:
        """What a policy did with the balls, from the means over its evaluation episodes of the
        task's metrics and path metrics (``means``: {measure: mean}): a name results tables count
        seeds by (Baoding: "round", "swing" or "no swaps"); None for a task without such kinds
        or where ``means`` lacks what the kind needs."""
        ...


def lead_metric(task: Task, records: Iterable[Mapping] = ()) -> str:
    """The measure ``task``'s reports lead with: its ``selection_metric`` (Baoding: round rotations)
    where every one of ``records`` (evaluation records) holds its mean, else its headline metric (a
    task without one, or records from before it was measured)."""
    lead = task.selection_metric
    return lead if lead and all(f"{lead}_mean" in r for r in records) else task.headline_metric


def uniform(
    generator: torch.Generator, shape: tuple[int, ...], half_width: float, device: torch.device
) -> torch.Tensor:
    """U(-half_width, half_width) samples of ``shape`` drawn from ``generator``."""
    return (torch.rand(shape, generator=generator, device=device, dtype=torch.float64) * 2.0 - 1.0) * half_width


def clear_where(values: torch.Tensor, mask: torch.Tensor) -> None:
    """Zero, in place, the rows of ``values`` (B, ...) where ``mask`` (B,) bool is True."""
    values.masked_fill_(mask.view(-1, *([1] * (values.dim() - 1))), 0)


def set_state_parameter(state: object, fields: Mapping[str, str], name: str, value: float | torch.Tensor) -> None:
    """``Task.set_parameter`` for a task whose parameter ``name`` lives in ``state``'s () tensor
    field ``fields[name]``: copied in place (a tensor on the device is never read back)."""
    if name not in fields:
        raise ValueError(f"unknown task parameter {name!r}; this task's parameters: {sorted(fields)}")
    field = getattr(state, fields[name])
    field.copy_(torch.as_tensor(value, dtype=field.dtype, device=field.device))

"""Bounce: bounce a 70 mm ball on the palm as often as possible in 10 s (docs/spec.md §5)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import torch

from roto.robots import pair_references
from roto.robots.spec import RobotSpec
from roto.sim.scene import BallSpec
from roto.tasks.arrays import as_dtype_of, squared_norm, where
from roto.tasks.base import (
    PALM_DROP_LIMIT,
    Marker,
    StepResult,
    TaskInputs,
    clear_where,
    set_state_parameter,
    uniform,
)

BALL = BallSpec(name="ball", radius=0.035, mass=0.030, friction=1.0)
SPAWN_HEIGHT = 0.10
"""Ball centre height above the palm centre at reset (m)."""
SPAWN_NOISE = 0.01
"""Half-width of the uniform spawn offset per axis (m)."""
MIN_FLIGHT_STEPS = 5
"""A new contact counts only after this many consecutive control steps without contact."""
BOUNCE_REWARD = 10.0
HORIZONTAL_LIMIT = 0.2
"""A ball further than this from the palm centre horizontally ends the episode (m)."""
PARAMETER_FIELDS = MappingProxyType({"drop_penalty": "drop_penalty"})
"""{task parameter: the ``BounceState`` field that holds it}."""


@dataclass
class BounceState:
    """Per-env counters, each (B,)."""

    prev_contact: torch.Tensor  # bool: ball touched the hand in the previous step
    waiting: torch.Tensor  # bool: contact was lost since the last counted bounce
    steps_without_contact: torch.Tensor  # int64: consecutive steps without contact before now
    bounces: torch.Tensor  # int64: bounces this episode
    # the drop-penalty training aid (roto.envs.aids.drop_penalty); 0 (the benchmark) charges nothing
    drop_penalty: torch.Tensor  # () float64: reward charged when an episode ends with the ball lost


def bounce_counter(
    contact: torch.Tensor,
    prev_contact: torch.Tensor,
    waiting: torch.Tensor,
    steps_without_contact: torch.Tensor,
    min_flight_steps: int = MIN_FLIGHT_STEPS,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """One step of the bounce rule (pure; all inputs and outputs (B,), torch or numpy).

    A contact that follows ``min_flight_steps`` or more steps without contact is a valid new
    contact; it is a bounce if contact was lost since the last bounce. The first touchdown after a
    spawn is therefore not a bounce.

    Returns:
        (bounce bool, new waiting bool, new steps_without_contact int64)
    """
    new_contact = contact & ~prev_contact
    lost_contact = prev_contact & ~contact
    valid = new_contact & (steps_without_contact >= min_flight_steps)
    bounce = waiting & valid
    waiting = (waiting | lost_contact) & ~bounce
    steps_without_contact = where(contact, 0, steps_without_contact + 1)
    return bounce, waiting, steps_without_contact


class Bounce:
    """The Bounce task (robot-agnostic)."""

    name = "bounce"
    display_name = "Bounce"
    version = 0
    metric_names = ("bounces",)
    headline_metric = "bounces"
    reference_name = "scripted Bounce"

    @property
    def reference(self) -> Mapping[str, float]:
        """{robot: bounces per 10 s of its scripted policy} (``roto demo``), from each hand's record."""
        return pair_references(self.name)

    observation_size = 3
    selection_metric = None
    """``best.pt`` goes by the return, as roto's does."""
    path_metric_names = ()
    parameters = MappingProxyType({"drop_penalty": 0.0})
    """The parameter a training aid may change, at the benchmark's value: nothing charged for a lost ball."""

    def set_parameter(self, state: BounceState, name: str, value: float | torch.Tensor) -> None:
        """Set ``drop_penalty`` of every world (``Task.set_parameter``)."""
        set_state_parameter(state, PARAMETER_FIELDS, name, value)

    def balls(self, robot: RobotSpec) -> tuple[BallSpec, ...]:
        """One 70 mm, 30 g ball for every hand."""
        return (BALL,)

    def init_state(self, robot: RobotSpec, num_envs: int, device: torch.device) -> BounceState:
        """All counters at zero."""
        zeros_b = torch.zeros(num_envs, dtype=torch.bool, device=device)
        zeros_i = torch.zeros(num_envs, dtype=torch.int64, device=device)
        no_penalty = torch.zeros((), dtype=torch.float64, device=device)
        return BounceState(zeros_b, zeros_b.clone(), zeros_i, zeros_i.clone(), no_penalty)

    def reset(self, state: BounceState, mask: torch.Tensor) -> None:
        """Clear the counters of the worlds in ``mask`` (B,) bool."""
        for counter in (state.prev_contact, state.waiting, state.steps_without_contact, state.bounces):
            clear_where(counter, mask)

    def initial_ball_positions(self, state: BounceState, n: int, generator: torch.Generator) -> torch.Tensor:
        """(n, 1, 3): the ball ~10 cm above the palm centre plus U(±1 cm) per axis."""
        pos = uniform(generator, (n, 1, 3), SPAWN_NOISE, state.bounces.device)
        pos[..., 2] += SPAWN_HEIGHT
        return pos

    def step(self, state: BounceState, inputs: TaskInputs) -> StepResult:
        """Count bounces (hand-ball contact only), reward 10 per bounce, end on a dropped ball (a
        "drop" term charges ``drop_penalty`` then: 0 for the benchmark)."""
        contact = inputs.ball_contact[:, 0]
        bounce, state.waiting, state.steps_without_contact = bounce_counter(
            contact, state.prev_contact, state.waiting, state.steps_without_contact
        )
        state.prev_contact = contact
        state.bounces += bounce
        pos = inputs.ball_pos[:, 0]
        terminated = (pos[:, 2] < -PALM_DROP_LIMIT) | (squared_norm(pos[:, :2]) > HORIZONTAL_LIMIT**2)
        lost = as_dtype_of(terminated, pos) * as_dtype_of(state.drop_penalty, pos)
        terms = {"bounce": BOUNCE_REWARD * as_dtype_of(bounce, pos), "drop": -lost}
        return StepResult(reward_terms=terms, terminated=terminated)

    def metrics(self, state: BounceState) -> dict[str, torch.Tensor]:
        """Bounces so far this episode."""
        return {"bounces": state.bounces.to(torch.float32)}

    def observation(self, state: BounceState) -> torch.Tensor:
        """(B, 3): contact in the previous step, waiting for a bounce, and the flight so far as a share
        of the ``MIN_FLIGHT_STEPS`` a bounce needs (capped at 1); each in [0, 1]."""
        flight = (state.steps_without_contact.to(torch.float64) / MIN_FLIGHT_STEPS).clamp(max=1.0)
        return torch.stack([state.prev_contact.to(flight.dtype), state.waiting.to(flight.dtype), flight], dim=1)

    def markers(self, state: BounceState) -> list[Marker]:
        """None: Bounce has no targets."""
        return []

    def path_metrics(self, ball_path: torch.Tensor, metrics: Mapping[str, float]) -> dict[str, float]:
        """None: a bounce count says all the path does."""
        return {}

    def derived_metrics(self, episode: Mapping[str, float]) -> dict[str, float]:
        """None (no path metrics)."""
        return {}

    def path_kind(self, means: Mapping[str, float]) -> str | None:
        """None: a bounce has no kinds."""
        return None

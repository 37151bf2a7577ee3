"""Baoding: rotate two balls around each other in the hand as often as possible in 10 s (docs/spec.md §6)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import mujoco
import numpy as np
import torch

from roto.robots import pair_references
from roto.robots.spec import BaodingGeometry, RobotSpec
from roto.sim.scene import BallSpec, build_scene
from roto.tasks.arrays import Array, as_dtype_of, flip_rows, squared_norm, tanh, vector_norm, where, zero_on_host
from roto.tasks.base import (
    PALM_DROP_LIMIT,
    Marker,
    StepResult,
    TaskInputs,
    clear_where,
    set_state_parameter,
    uniform,
)
from roto.tasks.pair_turns import pair_turns
from roto.tasks.round_swaps import paid_swaps, pair_turn_step, turn_pay_share, turn_shaping

BALL_MASS = 0.055
SUCCESS_RADIUS = 0.01
"""A ball within this distance of its current target sets its latch (m)."""
SWAP_REWARD = 10.0
PARAMETER_FIELDS = MappingProxyType(
    {
        "success_radius": "radius",
        "swap_min_turn": "min_turn",
        "swap_first_paid": "first_paid",
        "turn_reward": "turn_reward",
        "turn_lead": "turn_lead",
        "turn_near": "turn_near",
        "turn_soft": "turn_soft",
    }
)
"""{task parameter: the ``BaodingState`` field that holds it}."""
UNBOUNDED_LEAD = 1e9
"""``turn_lead`` of the turn-shaping aid when its paid turning is not bounded by the swaps (turns)."""
ANYWHERE = 1e9
"""``turn_near`` of the turn-shaping aid when turning pays wherever the pair is (half target separations)."""
DENSE_SCALE = 0.1
DENSE_LENGTH = 0.1
"""Dense reward 0.1 · Σ (1 − tanh(d / 0.1)) per step."""
ROUND_SHARE = 0.8
"""A policy goes round when its mean net turns are at least this share of its mean rotations by
roto's count (``path_kind``); a swing out and back makes about 0.25 net turns however often it swaps."""
MAX_SEPARATION = 0.15
"""Balls this far apart end the episode (m)."""
RESET_NOISE = 0.005
"""Half-width of the shared uniform offset of both balls at reset (m)."""
DROP_SPACING = 0.04
"""The balls are dropped side by side this far apart along the fingers (x), ball a nearer the tips
(m), or a diameter + ``DROP_GAP`` apart where that is more (the Allegro's 2-inch balls)."""
DROP_GAP = 0.001


BALL_COLOURS = ((0.85, 0.65, 0.15), (0.2, 0.45, 0.85))
"""RGB of ball a (gold) and ball b (blue); their targets are drawn in the same colours."""


def baoding_balls(radius: float) -> tuple[BallSpec, ...]:
    """Two 55 g balls of the given radius (distinct colours)."""
    return tuple(
        BallSpec(name=name, radius=radius, mass=BALL_MASS, rgba=(*rgb, 1.0))
        for name, rgb in zip(("ball_a", "ball_b"), BALL_COLOURS, strict=True)
    )


def drop_spacing(radius: float) -> float:
    """Distance (m) between the dropped balls' centres: roto's 4 cm, or 2r + 1 mm if more."""
    return max(DROP_SPACING, 2.0 * radius + DROP_GAP)


def drop_positions(centre: torch.Tensor, radius: float) -> torch.Tensor:
    """(2, 3): where the balls are dropped from, side by side along x about ``centre`` (3,)."""
    half = torch.tensor([0.5 * drop_spacing(radius), 0.0, 0.0], dtype=centre.dtype, device=centre.device)
    return torch.stack([centre + half, centre - half])


def geometry_of(robot: RobotSpec) -> BaodingGeometry:
    """The robot's Baoding geometry, from its record of the pair (``PairRecord.geometry``).

    Raises:
        ValueError naming the robot when its record has none.
    """
    record = robot.tasks.get("baoding")
    if record is None or record.geometry is None:
        raise ValueError(f"robot {robot.name!r} has no Baoding geometry in its record (tasks['baoding'].geometry)")
    return record.geometry


def rest_after_drop(robot: RobotSpec, settle_steps: int = 600, substeps: int = 4) -> np.ndarray:
    """Where the two balls come to rest (2, 3), task frame, when dropped from the robot's drop
    positions (no offset) onto the hand holding its default pose for ``settle_steps`` control
    steps. Ball a's resting place is the hand's T_palm (docs/tasks.md)."""
    geometry = geometry_of(robot)
    radius = geometry.ball_radius
    model, layout = build_scene(robot, baoding_balls(radius))
    data = mujoco.MjData(model)
    data.qpos[:] = layout.default_qpos
    drop = drop_positions(torch.tensor(geometry.drop_centre, dtype=torch.float64), radius).numpy()
    for adr, start in zip(layout.ball_qpos, drop, strict=True):
        data.qpos[adr : adr + 3] = start
    data.ctrl[:] = layout.default_qpos[layout.act_qpos]
    mujoco.mj_step(model, data, nstep=settle_steps * substeps)
    return np.stack([data.qpos[adr : adr + 3].copy() for adr in layout.ball_qpos])


def check_setup(robot: RobotSpec) -> None:
    """Refuse Baoding targets closer together than 2r: balls on them would overlap.

    Raises:
        ValueError naming the hand and the distances. (Whether the drop starts the balls clear of
        the hand is checked where the env is made, and on every start: ``roto.envs.start_pool``.)
    """
    geometry = geometry_of(robot)
    radius = geometry.ball_radius
    t_a, t_b = np.asarray(geometry.targets, dtype=np.float64)
    gap = float(np.linalg.norm(t_a - t_b))
    if gap < 2.0 * radius:
        raise ValueError(
            f"robot {robot.name!r}: Baoding targets {gap * 1000:.1f} mm apart, closer than two ball radii "
            f"({2000 * radius:.1f} mm): balls on them would overlap"
        )


@dataclass
class BaodingState:
    """Per-env task state."""

    targets: torch.Tensor  # (2, 3) T_a, T_b, shared by all envs
    drop: torch.Tensor  # (2, 3) where ball a and ball b are dropped from, before the shared offset
    swapped: torch.Tensor  # (B,) bool: ball a aims at T_b and ball b at T_a
    latched: torch.Tensor  # (B, 2) bool: ball i has reached its current target
    swaps: torch.Tensor  # (B,) int64
    radius: torch.Tensor  # () float64: the success radius (SUCCESS_RADIUS; a training curriculum may widen it)
    # the round-swaps training aid (roto.tasks.round_swaps); min_turn 0 (the benchmark) pays every swap
    pair_angle: torch.Tensor  # (B,) float64: the ball line's angle (rad) at the last step
    angle_set: torch.Tensor  # (B,) bool: pair_angle holds a value this episode
    turned: torch.Tensor  # (B,) float64: the line's signed turns since the last paid swap
    direction: torch.Tensor  # (B,) float64: +1 or -1, the way round of the first paid swap; 0 before it
    min_turn: torch.Tensor  # () float64: turns a paid swap must follow (0: every swap is paid)
    first_paid: torch.Tensor  # () float64: > 0 pays an episode's first swap whatever turned before it
    # the turn-shaping training aid (roto.tasks.round_swaps.turn_shaping); turn_reward 0 (the benchmark) pays nothing
    net_turn: torch.Tensor  # (B,) float64: the line's signed turns this episode
    turn_reward: torch.Tensor  # () float64: reward per turn the pair's net turning grows by
    turn_lead: torch.Tensor  # () float64: turns the paid turning may run ahead of half a turn per swap
    turn_near: torch.Tensor  # () float64: turning pays with the pair's centre this many half target separations near
    turn_soft: torch.Tensor  # () float64: > 0: beyond turn_near the pay falls off as (near / offset)²


def baoding_rule(
    ball_pos: torch.Tensor,
    targets: torch.Tensor,
    swapped: torch.Tensor,
    latched: torch.Tensor,
    radius: float | torch.Tensor = SUCCESS_RADIUS,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """One step of the latch-and-swap rule (pure; torch or numpy).

    Args:
        ball_pos: (B, 2, 3) ball centres.
        targets: (2, 3) T_a, T_b.
        swapped: (B,) bool, current assignment (False: ball a -> T_a, ball b -> T_b).
        latched: (B, 2) bool latches.
        radius: a ball this near its current target (m) sets its latch.

    Returns:
        (distances (B, 2) to the targets used this step, swap (B,) bool, new swapped, new latched)
    """
    current = where(swapped[:, None, None], flip_rows(targets)[None], targets[None])
    dist = vector_norm(ball_pos - current)
    latched = latched | (dist < radius)
    swap = latched.all(axis=1)
    swapped = swapped ^ swap
    latched = latched & ~swap[:, None]
    return dist, swap, swapped, latched


def follow_turns(state: BaodingState, pos: Array, swap: Array) -> dict[str, Array]:
    """The training aids' part of a step: the ball line's turns (``state`` updated), the swaps they
    pay ("swap" (B,) bool: every swap while ``min_turn`` is 0) and the turn-shaping reward ("turn"
    (B,): 0 while ``turn_reward`` is 0). ``pos`` (B, 2, 3) ball centres, ``swap`` (B,) bool."""
    state.pair_angle, turn = pair_turn_step(pos, state.pair_angle, state.angle_set)
    state.angle_set = state.angle_set | True
    paid, state.turned, state.direction = paid_swaps(
        swap, state.turned + turn, state.direction, state.min_turn, state.first_paid
    )
    paid_turns = state.turn_lead + 0.5 * as_dtype_of(state.swaps, pos)  # turns the swaps so far back
    before = paid_turns - 0.5 * as_dtype_of(swap, pos)  # the bound before this step's swap
    share = turn_pay_share(pos, state.targets, state.turn_near, state.turn_soft)
    shaped, state.net_turn = turn_shaping(state.net_turn, turn, state.turn_reward, before, paid_turns, share)
    return {"swap": paid, "turn": shaped}


class Baoding:
    """The Baoding task (robot-agnostic; targets and ball size come from the robot record)."""

    name = "baoding"
    display_name = "Baoding"
    version = 1
    """v1: balls dropped from above, roto's diagonal (or side-by-side) targets; v0 started the balls
    on targets where they rest, partly inside the hand."""
    metric_names = ("swaps", "rotations")
    headline_metric = "rotations"
    parameters = MappingProxyType(
        {
            "success_radius": SUCCESS_RADIUS,
            "swap_min_turn": 0.0,
            "swap_first_paid": 0.0,
            "turn_reward": 0.0,
            "turn_lead": UNBOUNDED_LEAD,
            "turn_near": ANYWHERE,
            "turn_soft": 0.0,
        }
    )
    """What training aids may change: the latch radius (m; a tolerance curriculum starts it wider,
    ``roto.envs.aids.tolerance``), the turns a paid swap must follow (0: every swap is paid; the
    round-swaps aid sets it, ``roto.tasks.round_swaps``), whether an episode's first swap is paid
    without them (0: no; the same aid), the reward per turn of the pair's net turning (0: none; the
    turn-shaping aid sets it, ``roto.tasks.round_swaps.turn_shaping``), the turns that paid turning
    may run ahead of half a turn per swap (unbounded unless the aid's ``lead`` says), how near
    the targets the pair's centre must be for turning to pay (anywhere unless its ``near`` says) and
    whether beyond that the pay falls off instead of stopping (its ``soft``)."""
    reference_name = "reference controller"

    @property
    def reference(self) -> Mapping[str, float]:
        """{robot: rotations per 10 s of the predictive-sampling reference controller, 16 episodes}
        (``roto demo --task baoding``), from each hand's record."""
        return pair_references(self.name)

    observation_size = 8
    selection_metric = "round_rotations"
    """``best.pt`` goes by round rotations (a swing out and back scores about 0.25), then the return."""
    path_metric_names = ("net_turns", "travelled_turns", "round_rotations")
    """Whether the balls went round each other or swung out and back (``roto.tasks.pair_turns``): a
    swap counts either way; ``round_rotations`` counts only the rotations the pair's net turning
    backs (min(rotations, net turns) per episode: a swing scores its net turns, about 0.25)."""

    def balls(self, robot: RobotSpec) -> tuple[BallSpec, ...]:
        """Two 55 g balls of the robot's Baoding diameter."""
        return baoding_balls(geometry_of(robot).ball_radius)

    def init_state(self, robot: RobotSpec, num_envs: int, device: torch.device) -> BaodingState:
        """Targets and drop from the robot record; latches clear."""
        check_setup(robot)
        geometry = geometry_of(robot)
        targets = torch.tensor(geometry.targets, dtype=torch.float64, device=device)
        centre = torch.tensor(geometry.drop_centre, dtype=torch.float64, device=device)
        return BaodingState(
            targets=targets,
            drop=drop_positions(centre, geometry.ball_radius),
            swapped=torch.zeros(num_envs, dtype=torch.bool, device=device),
            latched=torch.zeros(num_envs, 2, dtype=torch.bool, device=device),
            swaps=torch.zeros(num_envs, dtype=torch.int64, device=device),
            radius=torch.tensor(SUCCESS_RADIUS, dtype=torch.float64, device=device),
            pair_angle=torch.zeros(num_envs, dtype=torch.float64, device=device),
            angle_set=torch.zeros(num_envs, dtype=torch.bool, device=device),
            turned=torch.zeros(num_envs, dtype=torch.float64, device=device),
            direction=torch.zeros(num_envs, dtype=torch.float64, device=device),
            min_turn=torch.zeros((), dtype=torch.float64, device=device),
            first_paid=torch.zeros((), dtype=torch.float64, device=device),
            net_turn=torch.zeros(num_envs, dtype=torch.float64, device=device),
            turn_reward=torch.zeros((), dtype=torch.float64, device=device),
            turn_lead=torch.tensor(UNBOUNDED_LEAD, dtype=torch.float64, device=device),
            turn_near=torch.tensor(ANYWHERE, dtype=torch.float64, device=device),
            turn_soft=torch.zeros((), dtype=torch.float64, device=device),
        )

    def set_parameter(self, state: BaodingState, name: str, value: float | torch.Tensor) -> None:
        """Set ``success_radius``, ``swap_min_turn``, ``swap_first_paid``, ``turn_reward``,
        ``turn_lead``, ``turn_near`` or ``turn_soft`` of every world (``Task.set_parameter``)."""
        set_state_parameter(state, PARAMETER_FIELDS, name, value)

    def reset(self, state: BaodingState, mask: torch.Tensor) -> None:
        """Clear the latches, swap count and assignment (ball a -> T_a, ball b -> T_b), and the ball
        line's turns, of the worlds in ``mask`` (B,) bool."""
        turns = (state.angle_set, state.turned, state.direction, state.net_turn)
        for latch in (state.swapped, state.latched, state.swaps, *turns):
            clear_where(latch, mask)

    def initial_ball_positions(self, state: BaodingState, n: int, generator: torch.Generator) -> torch.Tensor:
        """(n, 2, 3): both balls in the air above the hand, side by side along the fingers, plus one
        shared U(±5 mm)³ offset; they fall into the hand (roto's drop)."""
        offset = uniform(generator, (n, 1, 3), RESET_NOISE, state.targets.device)
        return state.drop[None] + offset

    def step(self, state: BaodingState, inputs: TaskInputs) -> StepResult:
        """Latch, swap (+10; with the round-swaps aid, only a swap that followed a turn), dense
        shaping (with the turn-shaping aid, a "turn" term too); end when the balls part or drop."""
        pos = inputs.ball_pos
        dist, swap, state.swapped, state.latched = baoding_rule(
            pos, state.targets, state.swapped, state.latched, state.radius
        )
        state.swaps += swap
        terms = {"swap": swap, "distance": DENSE_SCALE * (1.0 - tanh(dist / DENSE_LENGTH)).sum(axis=1)}
        if not (zero_on_host(state.min_turn) and zero_on_host(state.turn_reward)):  # an aid follows the turns
            terms.update(follow_turns(state, pos, swap))
        terms["swap"] = SWAP_REWARD * as_dtype_of(terms["swap"], pos)
        parted = squared_norm(pos[:, 0] - pos[:, 1]) >= MAX_SEPARATION**2
        dropped = (pos[:, :, 2] < -PALM_DROP_LIMIT).any(axis=1)
        return StepResult(reward_terms=terms, terminated=parted | dropped)

    def metrics(self, state: BaodingState) -> dict[str, torch.Tensor]:
        """Swaps and rotations (= swaps / 2) so far this episode."""
        swaps = state.swaps.to(torch.float32)
        return {"swaps": swaps, "rotations": swaps / 2.0}

    def observation(self, state: BaodingState) -> torch.Tensor:
        """(B, 8): each ball's current target (task frame, m), then its latch (0 or 1)."""
        current = torch.where(state.swapped[:, None, None], state.targets.flip(0)[None], state.targets[None])
        return torch.cat([current.flatten(1), state.latched.to(current.dtype)], dim=1)

    def markers(self, state: BaodingState) -> list[Marker]:
        """Each ball's current target, a translucent sphere of the success radius in the ball's colour."""
        current = self.observation(state)[:, :6].unflatten(1, (2, 3))
        return [
            Marker(pos=current[:, i], radius=SUCCESS_RADIUS, rgba=(*rgb, 0.35)) for i, rgb in enumerate(BALL_COLOURS)
        ]

    def path_metrics(self, ball_path: torch.Tensor, metrics: Mapping[str, float]) -> dict[str, float]:
        """Net and travelled turns of the line between the balls over the episode (``pair_turns``),
        and the episode's ``metrics["rotations"]`` that its net turns back (``derived_metrics``)."""
        net, travelled = pair_turns(ball_path)
        turns = {"net_turns": net, "travelled_turns": travelled}
        return turns | self.derived_metrics({**metrics, **turns})

    def derived_metrics(self, episode: Mapping[str, float]) -> dict[str, float]:
        """``round_rotations`` = min(rotations, net turns), where ``episode`` has both."""
        if "rotations" not in episode or "net_turns" not in episode:
            return {}
        return {"round_rotations": min(episode["rotations"], episode["net_turns"])}

    def path_kind(self, means: Mapping[str, float]) -> str | None:
        """The kind of a policy's paths: "no swaps" below one rotation per episode; else "round" when
        the mean net turns are at least ``ROUND_SHARE`` of the mean rotations (roto's count),
        "swing" when not; None without both means."""
        if "rotations" not in means or "net_turns" not in means:
            return None
        if means["rotations"] < 1.0:
            return "no swaps"
        return "round" if means["net_turns"] >= ROUND_SHARE * means["rotations"] else "swing"

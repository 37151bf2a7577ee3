"""The robot record: everything a task or a backend needs to know about one hand, as data."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import mujoco


@dataclass(frozen=True, kw_only=True)
class Gains:
    """Position-actuator gains for a group of joints (damping lives inside the actuator).

    Attributes:
        kp: proportional gain, N·m/rad.
        kv: derivative gain, N·m·s/rad (clamped by the actuator's force limit, as in PhysX).
    """

    kp: float
    kv: float


@dataclass(frozen=True, kw_only=True)
class BounceScript:
    """Parameters of the scripted Bounce policy (``roto.scripted``) for one robot (angles in rad,
    lengths in m)."""

    swing: dict[str, tuple[float, float, float]]
    """Swing joint -> (hold, wind-up, strike) target angles."""
    lean: dict[str, tuple[float, float]] = field(default_factory=dict)
    """Swing joint -> change of its (wind-up, strike) angle per metre of ball x offset from ``centre_x``."""
    pose: dict[str, float] = field(default_factory=dict)
    """Targets of other joints during the whole episode; the rest keep the default pose."""
    centre_x: float
    wind_up_steps: int
    strike_steps: int
    settle_speed: float
    """The ball counts as caught when it touches the hand with |vz| below this (m/s) for two steps."""


@dataclass(frozen=True, kw_only=True)
class BaodingGeometry:
    """Where Baoding's balls and targets go on one hand (docs/tasks.md).

    Attributes:
        ball_radius: the balls' radius on this hand (m).
        targets: T_a and T_b (task frame, m): roto's diagonal stack (``diagonal_stack``) or
            side-by-side pair (``side_by_side``) placed in this hand's cupped pose.
        drop_centre: midpoint (task frame, m) of the two balls when they are dropped at an episode
            start (each 2 cm from it along the fingers).
    """

    ball_radius: float
    targets: tuple[tuple[float, float, float], tuple[float, float, float]]
    drop_centre: tuple[float, float, float] = (0.0, 0.0, 0.09)


@dataclass(frozen=True, kw_only=True)
class PairRecord:
    """What belongs to one (task, hand) pair, measured on that hand (docs/robots.md).

    Attributes:
        reference: the task's reference (``Task.reference_name``: scripted Bounce, the Baoding
            reference controller) on this hand, in the task's headline metric per 10 s.
        warp_peaks: the most contacts and constraint rows any world needed
            (``benchmarks/contact_peaks.py``); the Warp backend sizes its buffers from them
            (``warp_capacity``).
        recipe: the packaged agent config (``roto/configs/<recipe>.yaml``, training aids included)
            that trains this pair's baseline on a 2-core CPU: what a plan's ``{recipe}`` names.
        script: Bounce: the scripted motion whose bounces are ``reference`` (``roto.scripted``).
        geometry: Baoding: where its balls and targets go on this hand.
    """

    reference: float
    warp_peaks: tuple[int, int]
    recipe: str
    script: BounceScript | None = None
    geometry: BaodingGeometry | None = None

    @property
    def warp_capacity(self) -> tuple[int, int]:
        """(nconmax, njmax) per world the Warp backend allocates for the pair: MuJoCo Warp sizes
        its contact and constraint-row buffers once, and a world that needs more loses contacts,
        so the measured peaks (32 worlds x 600 control steps of a random-action and a held-pose
        workload on the CPU backend) are doubled and rounded up, contacts to a multiple of 16 and
        rows to one of 32."""
        ncon, nefc = self.warp_peaks
        return 16 * math.ceil(2.0 * ncon / 16), 32 * math.ceil(2.0 * nefc / 32)


@dataclass(frozen=True, kw_only=True)
class RobotSpec:
    """One hand, described as data.

    Attributes:
        name: registry name (lower case, e.g. ``"shadow"``).
        display_name: name used in Gymnasium ids (e.g. ``"Shadow"``).
        load_spec: returns a fresh ``mujoco.MjSpec`` of the hand alone (no world, no objects).
        root_body: the body that carries the whole hand; it is re-posed into the task frame.
        actuated_joints: joint names in action order; each has one position actuator.
        observed_joints: joint names whose position and velocity are observed, in order.
        tactile_links: body names that each give one tactile bit, in observation order.
        gains: joint-name prefix/suffix pattern -> gains; first matching key wins (see ``gains_for``).
        default_pose: joint name -> angle (rad) of the cupped resting pose; missing joints are 0.
        palm_geom: the collision geom whose top face is the palm surface.
        knuckle_bodies: finger base bodies, index finger first and little (or last) finger last.
        tip_bodies: distal finger bodies, used to find the finger direction.
        tasks: task name -> the pair's record (``PairRecord``): what was measured of this hand on
            that task.
        thumb_tip: the thumb's distal body (with ``tip_bodies`` and the palm: where taxels lie).
        coupled_joints: driven joint -> (driving joint, ratio): the model couples them (tendon or
            equality); resets set driven = ratio * driving so no coupling starts violated.
        excluded_contacts: body pairs whose contacts are filtered out.
        palm_tilt: (about x, about y) rotation (rad) of the whole hand about the palm centre after
            it is posed palm-up, for hands whose palm alone cannot cradle a ball (e.g. a hand with
            no little finger). Positive y tilts the fingertips down; positive x lowers the side
            of the first finger (the thumb side).
    """

    name: str
    display_name: str
    load_spec: Callable[[], mujoco.MjSpec]
    root_body: str
    actuated_joints: tuple[str, ...]
    observed_joints: tuple[str, ...]
    tactile_links: tuple[str, ...]
    gains: Mapping[str, Gains]
    default_pose: Mapping[str, float]
    palm_geom: str
    knuckle_bodies: tuple[str, ...]
    tip_bodies: tuple[str, ...]
    thumb_tip: str
    coupled_joints: Mapping[str, tuple[str, float]] = field(default_factory=dict)
    excluded_contacts: tuple[tuple[str, str], ...] = field(default=())
    palm_tilt: tuple[float, float] = (0.0, 0.0)
    tasks: Mapping[str, PairRecord] = field(default_factory=dict)

    def gains_for(self, joint: str) -> Gains:
        """The gains of one actuated joint: the first key of ``gains`` contained in its name."""
        for key, gains in self.gains.items():
            if key in joint:
                return gains
        raise KeyError(f"robot {self.name!r}: no gains for joint {joint!r}; keys are {list(self.gains)}")

    @property
    def num_actions(self) -> int:
        """Action dimension (one per actuated joint)."""
        return len(self.actuated_joints)


Point = tuple[float, float, float]

DIAGONAL_CLEARANCE = 0.001
"""roto's diagonal stack: each coordinate of the raised target is 2r/√3 + 1 mm from T_palm."""
SIDE_BY_SIDE_GAP = 0.005
"""roto's side-by-side targets (its Allegro): centres 2r + 5 mm apart."""


def diagonal_stack(palm: Point, radius: float, signs: Point = (1.0, 1.0, 1.0)) -> tuple[Point, Point]:
    """roto's Baoding targets: T_palm and T_palm + δ·signs, δ = 2r/√3 + 1 mm (the balls' centres
    2r + √3 mm apart, one raised above the other when ``signs[2]`` is 1)."""
    delta = 2.0 * radius / 3.0**0.5 + DIAGONAL_CLEARANCE
    return tuple(palm), tuple(p + delta * s for p, s in zip(palm, signs, strict=True))


def side_by_side(palm: Point, radius: float, direction: Point) -> tuple[Point, Point]:
    """Targets T_palm and T_palm + (2r + 5 mm)·direction/|direction| (roto's Allegro placement)."""
    norm = sum(d * d for d in direction) ** 0.5
    spacing = 2.0 * radius + SIDE_BY_SIDE_GAP
    return tuple(palm), tuple(p + spacing * d / norm for p, d in zip(palm, direction, strict=True))


def with_baoding_geometry(robot: RobotSpec, **changes: Any) -> RobotSpec:
    """``robot`` with its Baoding geometry changed (``BaodingGeometry`` fields: ``targets`` ...): a
    candidate placement to try (``benchmarks/baoding_placements.py``), or a broken one to refuse."""
    record = robot.tasks["baoding"]
    geometry = dataclasses.replace(record.geometry, **changes)
    tasks = MappingProxyType({**robot.tasks, "baoding": dataclasses.replace(record, geometry=geometry)})
    return dataclasses.replace(robot, tasks=tasks)

"""The Baoding reference controller's cost: progress towards the next swap over a planned rollout.

Not the benchmark's reward. It plays the latch-and-swap rule forward along each rollout and
scores only the steps up to the rollout's first predicted swap: scoring the balls against their
new targets after a predicted swap makes the planner postpone the swap forever (the balls then
sit better for the next one), so a predicted swap is rewarded by how early it comes instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, kw_only=True)
class BaodingCostWeights:
    """Weights of the reference controller's cost terms.

    Attributes:
        distance: per metre of an unlatched ball's distance to its target, averaged over the steps
            before the first predicted swap.
        angle: per radian between the pair's axis (ball a -> ball b) and its target axis, averaged
            the same way (progress around the pair's midpoint).
        swap: bonus for a predicted swap, scaled by the share of the horizon left after it.
        drop: penalty for a rollout in which a ball falls below ``floor`` or the balls part, at any
            step (after a predicted swap too: a swap that drops the balls is no progress).
        action_rate: per rad² of change of the joint targets between control steps (mean).
        floor: height (m, task frame) below which a ball counts as falling.
        max_separation: distance (m) between the balls above which they count as parting.
        turn: per turn that the pair's axis still has to go, counter-clockwise seen from above
            (about the task frame's z, in the plane through the target axis nearest the horizontal),
            to reach its target axis, averaged like ``distance``. ``angle`` and ``distance`` have no
            direction, so the planner may swing the balls out and back; this term makes it carry
            them round one way. 0 (the default): off.
    """

    distance: float = 10.0
    angle: float = 0.3
    swap: float = 2.0
    drop: float = 10.0
    action_rate: float = 0.02
    floor: float = -0.06
    max_separation: float = 0.12
    turn: float = 0.0

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if not np.isfinite(value):
                raise ValueError(f"BaodingCostWeights.{name} must be finite, got {value!r}")
        if self.turn < 0:
            raise ValueError(f"BaodingCostWeights.turn must be >= 0 (0: off), got {self.turn!r}")


def baoding_rollout_cost(
    ball_pos: np.ndarray,
    targets: np.ndarray,
    swapped: bool,
    latched: np.ndarray,
    joint_targets: np.ndarray,
    radius: float,
    weights: BaodingCostWeights,
) -> np.ndarray:
    """Cost of N rollouts.

    Args:
        ball_pos: (N, H, 2, 3) ball centres at the end of each control step.
        targets: (2, 3) T_a, T_b.
        swapped: the world's current assignment (True: ball a aims at T_b).
        latched: (2,) bool, the world's current latches.
        joint_targets: (N, H, nu) the rollouts' joint targets.
        radius: success radius (m) of the latch rule.
        weights: the terms' weights.

    Returns:
        (N,) costs.
    """
    horizon = ball_pos.shape[1]
    aim = targets[::-1] if swapped else targets  # (2, 3) current target of ball a, ball b
    dist = np.linalg.norm(ball_pos - aim, axis=-1)  # (N, H, 2)
    latch = np.asarray(latched, dtype=bool)[None, None] | (np.cumsum(dist < radius, axis=1) > 0)
    both = latch.all(axis=-1)  # (N, H)
    swaps = both.any(axis=1)
    first = np.where(swaps, both.argmax(axis=1), horizon)  # step of the first predicted swap
    before = np.arange(horizon)[None] < first[:, None]  # (N, H) steps scored
    # the unlatched balls' distance, and the pair's axis against its target axis
    axis = ball_pos[:, :, 1] - ball_pos[:, :, 0]
    goal = aim[1] - aim[0]
    cos = (axis @ goal) / (np.linalg.norm(axis, axis=-1) * np.linalg.norm(goal) + 1e-9)
    angle = np.arccos(np.clip(cos, -1.0, 1.0))
    per_step = weights.distance * (dist * ~latch).sum(-1) + weights.angle * angle
    if weights.turn:
        per_step = per_step + weights.turn * turn_to_go(axis, goal)
    scored = np.maximum(before.sum(axis=1), 1)
    cost = (per_step * before).sum(axis=1) / scored
    cost -= weights.swap * swaps * (horizon - first) / horizon
    fell = (ball_pos[..., 2] < weights.floor).any(axis=(1, 2))
    parted = (np.linalg.norm(axis, axis=-1) > weights.max_separation).any(axis=1)
    cost += weights.drop * (fell | parted)
    rate = np.diff(joint_targets, axis=1)
    cost += weights.action_rate * (rate**2).sum(-1).mean(-1)
    return cost


def turn_to_go(axis: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Turns (in [0, 1)) that ``axis`` still has to rotate counter-clockwise, seen from above, to
    point along ``goal``: about the normal of the plane through ``goal`` nearest the horizontal.

    Args:
        axis: (..., 3) the pair's axis (ball a -> ball b).
        goal: (3,) the target axis (not vertical).

    Returns:
        (...,) turns to go; an axis just past the goal has almost a whole turn to go.
    """
    up = np.array([0.0, 0.0, 1.0])
    unit = goal / np.linalg.norm(goal)
    normal = up - (up @ unit) * unit
    size = np.linalg.norm(normal)
    if size < 1e-6:
        raise ValueError(f"target axis {goal.tolist()} is vertical: no plane nearest the horizontal")
    normal /= size
    signed = np.arctan2(np.cross(axis, goal) @ normal, axis @ goal)  # rotation from axis to goal about normal
    return np.mod(signed, 2 * np.pi) / (2 * np.pi)

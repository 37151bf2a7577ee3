"""A training-only aid for Baoding: pay a swap only where the balls went round each other.

roto's swap counts whichever way the balls traded places (``roto.tasks.pair_turns``), so a policy
may swing the pair out along an arc and back and score every swing. With this aid a training
env pays a swap's reward only when the line from ball a to ball b has turned, since the last swap
it paid, at least ``min_turn`` turns the same way round as the episode's first paid swap. A pair
carried round one way turns half a turn per swap and is paid for every swap; a pair swung out and
back is paid once an episode. The swap still happens and counts (the latches, the targets and the
swap metric are roto's); only the reward changes, and only where an env config asks for it
(``EnvConfig.swap_min_turn``, a training aid evaluation never uses).

The line is measured in the task frame's x-y plane (the palm's), where the balls roll.
"""

from __future__ import annotations

import math

from roto.tasks.arrays import Array, atan2, where


def pair_turn_step(ball_pos: Array, pair_angle: Array, angle_set: Array) -> tuple[Array, Array]:
    """The line's angle now and how far it turned since the last step (pure; torch or numpy).

    Args:
        ball_pos: (B, 2, 3) ball centres, task frame.
        pair_angle: (B,) the line's angle (rad) in the x-y plane at the last step.
        angle_set: (B,) bool, ``pair_angle`` holds a value (False on an episode's first step).

    Returns:
        (angle (B,) rad, turn (B,) signed turns since the last step, the shorter way; 0 where
        ``angle_set`` is False)
    """
    line = ball_pos[:, 1] - ball_pos[:, 0]
    angle = atan2(line[:, 1], line[:, 0])
    step = (angle - pair_angle + math.pi) % (2.0 * math.pi) - math.pi
    return angle, where(angle_set, step / (2.0 * math.pi), 0.0)


def paid_swaps(swap: Array, turned: Array, direction: Array, min_turn: float | Array) -> tuple[Array, Array, Array]:
    """Which swaps earn their reward (pure; torch or numpy).

    Args:
        swap: (B,) bool, a swap this step.
        turned: (B,) signed turns of the ball line since the last paid swap, this step's included.
        direction: (B,) +1 or -1, the way round of the episode's first paid swap; 0 before it.
        min_turn: the turns a paid swap must follow, the same way round; 0 pays every swap.

    Returns:
        (paid (B,) bool, new turned (0 where paid), new direction)
    """
    way = where(direction == 0, where(turned >= 0, 1.0, -1.0), direction)
    paid = swap & ((min_turn <= 0) | (turned * way >= min_turn))
    return paid, where(paid, 0.0, turned), where(paid, way, direction)

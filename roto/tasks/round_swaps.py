"""Training-only aids for Baoding that follow the line between the balls: pay a swap only where the
balls went round each other (``paid_swaps``), and pay the pair's net turning (``turn_shaping``).

roto's swap counts whichever way the balls traded places (``roto.tasks.pair_turns``), so a policy
may swing the pair out along an arc and back and score every swing. With the round-swaps aid a
training env pays a swap's reward only when the line from ball a to ball b has turned, since the last swap
it paid, at least ``min_turn`` turns the same way round as the episode's first paid swap. A pair
carried round one way turns half a turn per swap and is paid for every swap; a pair swung out and
back is paid once an episode. The swap still happens and counts (the latches, the targets and the
swap metric are roto's); only the reward changes, and only where an env config asks for it
(``EnvConfig.swap_min_turn``, a training aid evaluation never uses). With the turn-shaping aid
(``EnvConfig.turn_reward``) a training env also earns a reward for each turn the pair's net
turning this episode grows, and gives it back as the turning shrinks.

The line is measured in the task frame's x-y plane (the palm's), where the balls roll.
"""

from __future__ import annotations

import math

from roto.tasks.arrays import Array, atan2, minimum, vector_norm, where


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


def paid_swaps(
    swap: Array, turned: Array, direction: Array, min_turn: float | Array, first_paid: float | Array = 0.0
) -> tuple[Array, Array, Array]:
    """Which swaps earn their reward (pure; torch or numpy).

    Args:
        swap: (B,) bool, a swap this step.
        turned: (B,) signed turns of the ball line since the last paid swap, this step's included.
        direction: (B,) +1 or -1, the way round of the episode's first paid swap; 0 before it.
        min_turn: the turns a paid swap must follow, the same way round; 0 pays every swap.
        first_paid: > 0: an episode's first swap is paid however little the line turned before it
            (its way round, the sign of ``turned``, becomes the episode's); 0: it too must follow
            ``min_turn``.

    Returns:
        (paid (B,) bool, new turned (0 where paid), new direction)
    """
    way = where(direction == 0, where(turned >= 0, 1.0, -1.0), direction)
    paid = swap & ((min_turn <= 0) | (turned * way >= min_turn) | ((first_paid > 0) & (direction == 0)))
    return paid, where(paid, 0.0, turned), where(paid, way, direction)


def turn_shaping(
    net_turn: Array,
    turn: Array,
    turn_reward: float | Array,
    cap: Array | float,
    new_cap: Array | float,
    share: Array | float = 1.0,
) -> tuple[Array, Array]:
    """The turn-shaping reward: ``turn_reward`` per turn the pair's paid turning grows (pure; torch
    or numpy).

    A potential-based shaping term with potential ``turn_reward * min(|net turns|, cap)``: over an
    episode it sums to ``turn_reward * min(|net turns|, cap)`` at its end, so a pair carried round
    one way earns it for every turn and a swing out and back earns nothing (it pays on the way out
    what it takes back on the way back); either way round counts. ``cap`` bounds the paid turning
    by the swaps made (Baoding: ``turn_lead`` turns plus half a turn per swap), so spinning the pair
    faster than the balls trade places stops paying; an unbounded cap pays every turn.

    Args:
        net_turn: (B,) signed turns of the ball line so far this episode.
        turn: (B,) signed turns this step (``pair_turn_step``).
        turn_reward: reward per turn (0: the benchmark, nothing paid).
        cap, new_cap: (B,) the paid turning's bound before and after this step.
        share: (B,) the share of this step's growth that is paid (bool or float in [0, 1]; Baoding:
            ``turn_pay_share``, lower with the pair's centre away from the targets); shrinking is
            charged in full wherever it happens. Below 1 the term is no longer potential-based, but
            no closed loop earns anything: a turn made at a lower share and undone at a higher one,
            or the reverse, sums to at most 0.

    Returns:
        (reward (B,), new net_turn (B,))
    """
    net = net_turn + turn
    grown = minimum(abs(net), new_cap) - minimum(abs(net_turn), cap)
    return turn_reward * where(grown < 0, grown, share * grown), net


def centre_offset(ball_pos: Array, targets: Array) -> Array:
    """How far the pair's centre is from the targets' midpoint, in half the targets' separation
    (pure; torch or numpy).

    Args:
        ball_pos: (B, 2, 3) ball centres, task frame.
        targets: (2, 3) the two targets.

    Returns:
        (B,) float.
    """
    half = vector_norm(targets[0] - targets[1]) / 2.0
    return vector_norm((ball_pos[:, 0] + ball_pos[:, 1]) / 2.0 - (targets[0] + targets[1]) / 2.0) / half


def turn_pay_share(ball_pos: Array, targets: Array, near: float | Array, soft: float | Array = 0.0) -> Array:
    """The share of the pair's turning that turn shaping pays, by where the pair is (pure; torch or
    numpy): 1 with its centre within ``near`` half target separations of the targets' midpoint
    (``centre_offset``); beyond, nothing, or with ``soft`` > 0 (near / offset)², so that turning
    the pair nearer the targets always pays more and turning it anywhere pays something.

    Args:
        ball_pos: (B, 2, 3) ball centres, task frame.
        targets: (2, 3) the two targets.
        near: half target separations (large: everywhere).
        soft: > 0: the share falls off beyond ``near``; 0: it drops to 0 there.

    Returns:
        (B,) float in [0, 1].
    """
    offset = centre_offset(ball_pos, targets)
    falling = (soft > 0) * (near / where(offset > 0, offset, 1.0)) ** 2  # soft: a bool or a () tensor
    return where(offset < near, 1.0, falling)

"""How two balls trade places: turning around each other, or swinging back and forth.

Baoding counts a swap whenever each ball comes within the latch radius of the other's target,
whichever way the balls went. Two policies with the same swap count can differ: one carries the
pair round and round (the line from one ball to the other keeps turning the same way), the other
swings it through part of a turn and back. ``pair_turns`` tells them apart from the balls' paths.
"""

from __future__ import annotations

import math

import torch


def pair_turns(ball_pos: torch.Tensor) -> tuple[float, float]:
    """Net and travelled turns of the line from ball 0 to ball 1 over one episode.

    The line's direction is measured in the plane it sweeps most (spanned by the two largest
    principal directions of its second-moment matrix), step to step with the shorter of the two
    ways round, so steps must be short against half a turn.

    Args:
        ball_pos: (T, 2, 3) both balls' centres at each of T steps, in any fixed frame.

    Returns:
        (net, travelled): |sum of signed angle steps| / 2 pi and sum of |angle steps| / 2 pi. Both
        about equal to the rotations of a pair carried round one way; net near 0 for a swing that
        comes back.
    """
    if ball_pos.ndim != 3 or ball_pos.shape[1:] != (2, 3):
        raise ValueError(f"ball_pos must have shape (T, 2, 3), got {tuple(ball_pos.shape)}")
    if ball_pos.shape[0] < 2:
        return 0.0, 0.0
    line = (ball_pos[:, 1] - ball_pos[:, 0]).to(torch.float64)  # (T, 3)
    _, vectors = torch.linalg.eigh(line.T @ line)  # ascending eigenvalues; columns are directions
    first, second = vectors[:, 2], vectors[:, 1]
    angle = torch.atan2(line @ second, line @ first)  # (T,)
    step = torch.remainder(angle.diff() + math.pi, 2 * math.pi) - math.pi  # each in [-pi, pi)
    return abs(float(step.sum())) / (2 * math.pi), float(step.abs().sum()) / (2 * math.pi)

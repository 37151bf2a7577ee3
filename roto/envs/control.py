"""Action -> joint targets (docs/spec.md §2), as pure functions."""

from __future__ import annotations

import torch


def action_to_target(action: torch.Tensor, lo: torch.Tensor, hi: torch.Tensor) -> torch.Tensor:
    """Joint targets q* = lo + (clip(a, -1, 1) + 1) / 2 · (hi - lo).

    Args:
        action: (B, n) policy action.
        lo, hi: (n,) joint limits of the actuated joints.

    Returns:
        (B, n) joint position targets (rad).
    """
    return lo + (action.clamp(-1.0, 1.0) + 1.0) * 0.5 * (hi - lo)


def smooth_target(target: torch.Tensor, previous: torch.Tensor, alpha: float) -> torch.Tensor:
    """Exponential smoothing alpha · target + (1 - alpha) · previous (alpha = 1: none); shapes (B, n)."""
    if alpha == 1.0:
        return target
    return alpha * target + (1.0 - alpha) * previous


def target_to_action(target: torch.Tensor, lo: torch.Tensor, hi: torch.Tensor) -> torch.Tensor:
    """The action that ``action_to_target`` maps to ``target``: 2 (q* - lo) / (hi - lo) - 1, float32.

    Args:
        target: (..., n) joint targets (rad).
        lo, hi: (n,) joint limits of the actuated joints.

    Returns:
        (..., n) actions in [-1, 1] for targets within the limits.
    """
    return (2.0 * (target - lo) / (hi - lo) - 1.0).to(torch.float32)

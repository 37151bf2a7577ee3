"""Checks of the action an env is stepped with: pure functions, each raising a clear error."""

from __future__ import annotations

import math
from typing import Any

import torch


def check_action_layout(action: Any, expected: tuple[int, int], device: torch.device) -> torch.Tensor:
    """``action`` if it is a floating-point tensor of shape ``expected`` (num_envs, num_actions) on
    ``device``; otherwise TypeError or ValueError naming what is wrong and what is expected."""
    if not isinstance(action, torch.Tensor):
        raise TypeError(f"action must be a torch.Tensor of shape {expected}, got {type(action).__name__}")
    if tuple(action.shape) != expected:
        raise ValueError(f"action shape {tuple(action.shape)} is wrong; expected (num_envs, num_actions) = {expected}")
    if not action.is_floating_point():
        raise TypeError(f"action dtype {action.dtype} is not floating point; use torch.float32 or torch.float64")
    if action.device != device:
        raise ValueError(f"action is on device {action.device}; this env runs on {device}")
    return action


def check_action_finite(action: torch.Tensor) -> None:
    """Raise ValueError naming the envs (rows of the (B, n) ``action``) with a NaN or inf.

    One reduction instead of an element-wise check: a NaN or inf anywhere makes the sum non-finite;
    a sum that overflowed from finite values is told apart by the full check. Reads the device
    (a host sync): envs that step without one check periodically instead."""
    if not math.isfinite(float(action.sum())):
        bad = torch.nonzero(~torch.isfinite(action).all(dim=1)).flatten().tolist()
        if bad:
            raise ValueError(f"action has non-finite values (NaN or inf) in envs {bad[:10]}; actions must be finite")

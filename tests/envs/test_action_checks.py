"""The action checks on their own: layout errors name the problem; the finite check names the bad
envs and lets a finite action whose sum overflows through."""

import pytest
import torch

from roto.envs.action_checks import check_action_finite, check_action_layout

CPU = torch.device("cpu")


def test_a_well_formed_action_passes_and_each_flaw_is_named():
    action = torch.zeros(3, 2)
    assert check_action_layout(action, (3, 2), CPU) is action
    with pytest.raises(TypeError, match=r"must be a torch.Tensor of shape \(3, 2\), got list"):
        check_action_layout([[0.0, 0.0]] * 3, (3, 2), CPU)
    with pytest.raises(ValueError, match=r"action shape \(2, 3\) is wrong; expected .* = \(3, 2\)"):
        check_action_layout(torch.zeros(2, 3), (3, 2), CPU)
    with pytest.raises(TypeError, match=r"dtype torch\.int32 is not floating point"):
        check_action_layout(torch.zeros(3, 2, dtype=torch.int32), (3, 2), CPU)
    with pytest.raises(ValueError, match="action is on device meta; this env runs on cpu"):
        check_action_layout(torch.zeros(3, 2, device="meta"), (3, 2), CPU)


def test_the_finite_check_names_the_envs_with_nan_or_inf_and_passes_an_overflowing_sum():
    action = torch.zeros(4, 2)
    action[1, 0], action[3, 1] = float("nan"), float("-inf")
    with pytest.raises(ValueError, match=r"non-finite values \(NaN or inf\) in envs \[1, 3\]"):
        check_action_finite(action)
    huge = torch.full((4, 2), 3.0e38)  # finite, but its float32 sum overflows to inf
    assert not torch.isfinite(huge.sum())
    check_action_finite(huge)

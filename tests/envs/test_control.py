import pytest
import torch

from roto.envs.control import action_to_target, smooth_target, target_to_action

LO = torch.tensor([-1.0, 0.0, -0.5], dtype=torch.float64)
HI = torch.tensor([1.0, 1.5, 0.25], dtype=torch.float64)


def test_actions_map_linearly_onto_the_joint_limits_and_are_clipped():
    target = action_to_target(torch.tensor([[-1.0, 0.0, 1.0], [-3.0, 3.0, 0.5]], dtype=torch.float64), LO, HI)
    assert target[0].tolist() == pytest.approx([-1.0, 0.75, 0.25])
    assert target[1].tolist() == pytest.approx([-1.0, 1.5, 0.0625])


def test_target_to_action_inverts_action_to_target():
    action = torch.tensor([[-1.0, -0.3, 0.8], [0.5, 1.0, 0.0]])
    back = target_to_action(action_to_target(action.to(torch.float64), LO, HI), LO, HI)
    assert back.dtype == torch.float32
    torch.testing.assert_close(back, action)


def test_smoothing_blends_with_the_previous_target():
    new, old = torch.tensor([1.0]), torch.tensor([0.0])
    assert smooth_target(new, old, 1.0) is new
    assert smooth_target(new, old, 0.25).item() == pytest.approx(0.25)

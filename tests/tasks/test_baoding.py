import pytest
import torch

from roto.robots import get_robot
from roto.robots.spec import with_baoding_geometry
from roto.tasks.baoding import DROP_SPACING, RESET_NOISE, Baoding, baoding_rule, drop_spacing, geometry_of
from roto.tasks.base import TaskInputs

SHADOW = get_robot("shadow")
TARGETS = torch.tensor(geometry_of(SHADOW).targets, dtype=torch.float64)


def _inputs(pos_a, pos_b) -> TaskInputs:
    pos = torch.tensor([[pos_a, pos_b]], dtype=torch.float64)
    return TaskInputs(ball_pos=pos, ball_vel=torch.zeros_like(pos), ball_contact=torch.ones(1, 2, dtype=torch.bool))


def test_latches_then_swap_with_reward():
    task = Baoding()
    state = task.init_state(SHADOW, 1, torch.device("cpu"))
    t_a, t_b = TARGETS.tolist()
    far = [0.0, 0.1, 0.05]
    r1 = task.step(state, _inputs(t_a, far))  # ball a latches, b far
    assert state.latched.tolist() == [[True, False]] and r1.reward_terms["swap"][0] == 0
    r2 = task.step(state, _inputs(far, t_b))  # a left again (latch holds), b arrives -> swap
    assert r2.reward_terms["swap"][0] == 10.0
    assert state.swapped.tolist() == [True] and state.latched.tolist() == [[False, False]]
    assert task.metrics(state)["swaps"].tolist() == [1.0] and task.metrics(state)["rotations"].tolist() == [0.5]
    # targets are now swapped: a must reach T_b and b T_a
    r3 = task.step(state, _inputs(t_a, t_b))
    assert r3.reward_terms["swap"][0] == 0 and state.latched.tolist() == [[False, False]]
    r4 = task.step(state, _inputs(t_b, t_a))
    assert r4.reward_terms["swap"][0] == 10.0 and task.metrics(state)["rotations"].tolist() == [1.0]


def test_dense_reward_matches_formula():
    task = Baoding()
    state = task.init_state(SHADOW, 1, torch.device("cpu"))
    t_a, t_b = TARGETS
    pos_a = t_a + torch.tensor([0.03, 0.0, 0.0], dtype=torch.float64)
    pos_b = t_b + torch.tensor([0.0, 0.04, 0.0], dtype=torch.float64)
    result = task.step(state, _inputs(pos_a.tolist(), pos_b.tolist()))
    expected = 0.1 * ((1 - torch.tanh(torch.tensor(0.3))) + (1 - torch.tanh(torch.tensor(0.4))))
    torch.testing.assert_close(result.reward_terms["distance"][0].float(), expected, rtol=1e-5, atol=1e-6)


def test_rule_distance_uses_current_assignment():
    pos = torch.stack([TARGETS[1], TARGETS[0]])[None]
    dist, swap, swapped, _latched = baoding_rule(
        pos, TARGETS, torch.tensor([True]), torch.zeros(1, 2, dtype=torch.bool)
    )
    assert torch.allclose(dist, torch.zeros(1, 2, dtype=torch.float64)) and swap[0] and not swapped[0]


def test_terminations():
    task = Baoding()
    state = task.init_state(SHADOW, 1, torch.device("cpu"))
    assert not task.step(state, _inputs([0, 0, 0.01], [0.1, 0, 0.01])).terminated[0]
    assert task.step(state, _inputs([0, 0, 0.01], [0.16, 0, 0.01])).terminated[0]
    assert task.step(state, _inputs([0, 0, -0.21], [0.03, 0, 0.01])).terminated[0]


def test_reset_clears_state_and_drops_the_balls_side_by_side_from_above():
    task = Baoding()
    state = task.init_state(SHADOW, 2, torch.device("cpu"))
    state.swapped[:] = True
    state.latched[:] = True
    state.swaps[:] = 3
    task.reset(state, torch.tensor([False, True]))
    assert state.swapped.tolist() == [True, False] and state.swaps.tolist() == [3, 0]
    assert state.latched.tolist() == [[True, True], [False, False]]
    pos = task.initial_ball_positions(state, 64, torch.Generator().manual_seed(0))
    centre = torch.tensor(geometry_of(SHADOW).drop_centre, dtype=torch.float64)
    half = torch.tensor([[DROP_SPACING / 2, 0, 0], [-DROP_SPACING / 2, 0, 0]], dtype=torch.float64)
    offset = pos - (centre + half)
    assert torch.all(offset.abs() <= RESET_NOISE)
    torch.testing.assert_close(offset[:, 0], offset[:, 1], atol=1e-15, rtol=0)  # one shared offset
    assert float(offset.abs().max()) > 0.004  # the offset is drawn, not zero
    assert torch.all(pos[..., 2] > 0.08)  # 9 cm above the palm: they fall into the hand


def test_the_allegro_s_larger_balls_are_dropped_a_diameter_and_1mm_apart():
    allegro = get_robot("allegro")
    assert drop_spacing(geometry_of(allegro).ball_radius) == pytest.approx(2 * 0.0254 + 0.001)
    assert drop_spacing(geometry_of(SHADOW).ball_radius) == DROP_SPACING


def test_targets_closer_than_two_radii_are_refused_naming_the_hand_and_distances():
    t_palm = geometry_of(SHADOW).targets[0]
    close = with_baoding_geometry(SHADOW, targets=(t_palm, (t_palm[0] + 0.03, t_palm[1], t_palm[2])))
    with pytest.raises(ValueError, match=r"robot 'shadow': Baoding targets 30\.0 mm apart.*\(38\.1 mm\)"):
        Baoding().init_state(close, 1, torch.device("cpu"))

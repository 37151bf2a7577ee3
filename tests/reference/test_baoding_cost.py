"""The reference controller's cost: a swap predicted sooner is cheaper, nothing after it counts,
latched balls and falling balls are scored as documented."""

import numpy as np
import pytest

from roto.reference.baoding_cost import BaodingCostWeights, baoding_rollout_cost, turn_to_go

TARGETS = np.array([[0.0, 0.0, 0.0], [0.03, 0.0, 0.02]])
H = 10
NO_LATCH = np.zeros(2, dtype=bool)


def rollouts(*paths) -> np.ndarray:
    """(N, H, 2, 3) from per-rollout lists of (ball a, ball b) positions, the last one held."""
    out = np.zeros((len(paths), H, 2, 3))
    for n, path in enumerate(paths):
        for t in range(H):
            out[n, t] = path[min(t, len(path) - 1)]
    return out


def cost(pos, swapped=False, latched=NO_LATCH, weights=None, joint_targets=None):
    joint_targets = np.zeros((len(pos), H, 3)) if joint_targets is None else joint_targets
    return baoding_rollout_cost(pos, TARGETS, swapped, latched, joint_targets, 0.01, weights or BaodingCostWeights())


AWAY = (np.array([0.02, 0.02, 0.0]), np.array([0.05, 0.02, 0.0]))
ON = (TARGETS[0], TARGETS[1])


def test_an_earlier_swap_is_cheaper_and_no_swap_is_dearest():
    early = [AWAY] * 2 + [ON]
    late = [AWAY] * 7 + [ON]
    never = [AWAY]
    costs = cost(rollouts(early, late, never))
    assert costs[0] < costs[1] < costs[2]


def test_nothing_after_the_first_predicted_swap_counts():
    """After a swap the targets trade places; where the balls go then must not change the cost
    (scoring it made planners postpone the swap)."""
    stay = [AWAY] * 3 + [ON]
    wander = [AWAY] * 3 + [ON] + [(np.array([0.05, 0.0, 0.0]), np.array([0.0, 0.03, 0.01]))]  # still in hand
    a, b = cost(rollouts(stay, wander))
    assert a == b


def test_a_latched_ball_s_distance_is_not_scored():
    a_far = rollouts([(np.array([0.05, 0.0, 0.0]), np.array([0.05, 0.0, 0.02]))])  # a 5 cm from T_a, b 2 cm from T_b
    latched, unlatched = cost(a_far, latched=np.array([True, False])), cost(a_far)
    np.testing.assert_allclose(unlatched - latched, BaodingCostWeights().distance * 0.05, rtol=0, atol=1e-12)


def test_the_assignment_decides_which_target_a_ball_is_scored_against():
    on_own = rollouts([(TARGETS[0] + 0.02, TARGETS[1] + 0.02)])
    on_other = rollouts([(TARGETS[1] + 0.02, TARGETS[0] + 0.02)])
    np.testing.assert_allclose(cost(on_own), cost(on_other, swapped=True), rtol=0, atol=1e-12)


def test_a_falling_ball_or_parted_balls_pay_the_drop_penalty():
    weights = BaodingCostWeights()
    held = [AWAY]
    fell = [AWAY] * 5 + [(np.array([0.02, 0.02, -0.1]), AWAY[1])]
    parted = [AWAY] * 5 + [(np.array([-0.1, 0.02, 0.0]), AWAY[1])]
    base, after_fall, after_parting = cost(rollouts(held, fell, parted))
    assert after_fall - base > weights.drop * 0.9 and after_parting - base > weights.drop * 0.9


def test_jerky_targets_cost_more():
    pos = rollouts([AWAY], [AWAY])
    joint_targets = np.zeros((2, H, 3))
    joint_targets[1, ::2] = 0.5
    smooth, jerky = cost(pos, joint_targets=joint_targets)
    assert jerky > smooth


def rotate_about_z(vector, turns):
    c, s = np.cos(2 * np.pi * turns), np.sin(2 * np.pi * turns)
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1], vector[2]])


def test_turn_to_go_counts_the_counter_clockwise_way_round():
    goal = np.array([0.03, 0.0, 0.0])
    axes = np.stack([rotate_about_z(goal, t) for t in (0.0, -0.25, 0.25, -0.5, 0.01)])
    np.testing.assert_allclose(turn_to_go(axes, goal), [0.0, 0.25, 0.75, 0.5, 0.99], atol=1e-12)


def test_turn_to_go_in_a_tilted_plane():
    """The Shadow's diagonal targets: the goal axis climbs; turning about the normal of the plane
    through it nearest the horizontal still counts a quarter turn as a quarter."""
    goal = np.array([1.0, 1.0, 1.0])
    up = np.array([0.0, 0.0, 1.0])
    normal = up - (up @ goal) / (goal @ goal) * goal
    normal /= np.linalg.norm(normal)
    behind = np.cross(normal, goal)  # the goal rotated a quarter turn counter-clockwise about the normal
    assert abs(normal[0]) > 0.3  # the plane is tilted away from the horizontal
    axes = np.stack([-behind, behind, -goal, goal])
    np.testing.assert_allclose(turn_to_go(axes, goal), [0.25, 0.75, 0.5, 0.0], atol=1e-12)


def test_turn_to_go_refuses_a_vertical_goal():
    with pytest.raises(ValueError, match="vertical"):
        turn_to_go(np.ones((1, 3)), np.array([0.0, 0.0, 0.04]))


def test_the_turn_weight_makes_going_round_counter_clockwise_cheaper():
    """Two rollouts, mirror images: one carries the pair a quarter turn counter-clockwise, the other
    clockwise, neither reaching the targets. Without the turn term they cost the same; with it the
    counter-clockwise one is cheaper."""
    centre = (TARGETS[0] + TARGETS[1]) / 2
    half = (TARGETS[1] - TARGETS[0]) / 2
    start = rotate_about_z(half, 0.5)  # ball a where ball b's target is: half a turn to go either way
    paths = []
    for sign in (1, -1):
        paths.append(
            [
                (centre - rotate_about_z(start, sign * k / 40), centre + rotate_about_z(start, sign * k / 40))
                for k in range(H)
            ]
        )
    no_turn = cost(rollouts(*paths))
    np.testing.assert_allclose(no_turn[0], no_turn[1], rtol=0, atol=1e-12)
    ccw, cw = cost(rollouts(*paths), weights=BaodingCostWeights(turn=1.0))
    assert ccw < cw


def test_cost_weights_refuse_non_finite_values():
    with pytest.raises(ValueError, match="turn must be finite, got nan"):
        BaodingCostWeights(turn=float("nan"))
    with pytest.raises(ValueError, match=r"turn must be >= 0 \(0: off\), got -1.0"):
        BaodingCostWeights(turn=-1.0)

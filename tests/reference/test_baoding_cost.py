"""The reference controller's cost: a swap predicted sooner is cheaper, nothing after it counts,
latched balls and falling balls are scored as documented."""

import numpy as np

from roto.reference.baoding_cost import BaodingCostWeights, baoding_rollout_cost

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

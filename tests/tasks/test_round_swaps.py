"""The round-swaps training aid: a swap is paid only after the ball line turned the episode's way
round; a pair carried round is paid for every swap, a pair swung out and back once an episode,
and with the aid off every swap is paid as roto pays it. Swaps count as roto counts them either way."""

import math

import numpy as np
import pytest
import torch

import roto
from roto.envs.config import EnvConfig
from roto.rl.run_spec import RunSpec
from roto.robots import get_robot
from roto.tasks.baoding import SWAP_REWARD, Baoding, geometry_of
from roto.tasks.base import TaskInputs
from roto.tasks.round_swaps import paid_swaps, pair_turn_step

SHADOW = get_robot("shadow")


def test_the_line_turns_the_shorter_way_across_the_branch_cut_and_not_on_an_episodes_first_step():
    def balls(angle):  # ball b at `angle` round ball a, in the x-y plane, and a little above
        return torch.tensor([[[0.0, 0.0, 0.0], [math.cos(angle), math.sin(angle), 0.3]]], dtype=torch.float64)

    angle, turn = pair_turn_step(balls(0.9 * math.pi), torch.zeros(1, dtype=torch.float64), torch.tensor([False]))
    assert float(turn[0]) == 0.0 and float(angle[0]) == pytest.approx(0.9 * math.pi)
    angle, turn = pair_turn_step(balls(-0.9 * math.pi), angle, torch.tensor([True]))  # 0.2 pi on, past +pi
    assert float(turn[0]) == pytest.approx(0.1)
    _, turn = pair_turn_step(balls(0.9 * math.pi), angle, torch.tensor([True]))
    assert float(turn[0]) == pytest.approx(-0.1)


def run_rule(turns_between_swaps, min_turn, first_paid=0.0):
    """Paid flags of a sequence of swaps, each after the given signed turns of the line."""
    turned = torch.zeros(1, dtype=torch.float64)
    direction = torch.zeros(1, dtype=torch.float64)
    paid_flags = []
    for turn in turns_between_swaps:
        paid, turned, direction = paid_swaps(torch.tensor([True]), turned + turn, direction, min_turn, first_paid)
        paid_flags.append(bool(paid[0]))
    return paid_flags


@pytest.mark.parametrize("way", [1.0, -1.0])
def test_a_pair_carried_round_either_way_is_paid_for_every_swap(way):
    assert run_rule([way * 0.5] * 6, 0.25) == [True] * 6


def test_a_pair_swung_out_and_back_is_paid_once_and_without_the_aid_every_time():
    swing = [0.3, -0.3] * 4
    assert run_rule(swing, 0.25) == [True] + [False] * 7
    assert run_rule(swing, 0.0) == [True] * 8
    # a swing that turns back and then goes on round the first way is paid again once it has gone far enough
    assert run_rule([0.3, -0.3, 0.3, 0.5], 0.25) == [True, False, False, True]


def test_with_first_paid_an_episodes_first_swap_pays_after_any_turn_and_sets_the_way_round():
    # a replayed start a few steps before a swap: the first swap follows a tenth of a turn
    assert run_rule([0.1, 0.5, 0.5], 0.25) == [False, True, True]  # without: its reward withheld
    assert run_rule([0.1, 0.5, 0.5], 0.25, first_paid=1.0) == [True, True, True]
    # the first swap's way round (here clockwise, -0.1) is the episode's: a swing back is not paid
    assert run_rule([-0.1, 0.5, -0.5, -0.5], 0.25, first_paid=1.0) == [True, False, False, True]
    swing = [0.1, -0.3, 0.3, -0.3, 0.3]  # out and back along one arc: paid once an episode, as before
    assert run_rule(swing, 0.25, first_paid=1.0) == [True, False, False, False, False]


def test_a_step_without_a_swap_pays_nothing_and_keeps_counting_the_turn():
    paid, turned, direction = paid_swaps(
        torch.tensor([False, True]),
        torch.tensor([0.4, 0.1], dtype=torch.float64),
        torch.zeros(2, dtype=torch.float64),
        0.25,
    )
    assert paid.tolist() == [False, False] and turned.tolist() == [0.4, 0.1] and direction.tolist() == [0.0, 0.0]


def path_round_the_targets(thetas):
    """(T, 2, 3): the balls on a circle round the targets' midpoint, the line turned by each
    ``theta`` (rad) about the axis nearest the palm's normal (z) perpendicular to it; at theta = pi
    each ball sits on the other's target."""
    t_a, t_b = torch.tensor(geometry_of(SHADOW).targets, dtype=torch.float64)
    mid, half = (t_a + t_b) / 2, (t_b - t_a) / 2
    h = half / half.norm()
    z = torch.tensor([0.0, 0.0, 1.0], dtype=torch.float64)
    axis = z - (z @ h) * h
    axis = axis / axis.norm()
    out = []
    for theta in thetas:  # Rodrigues' rotation of `half` about `axis` (perpendicular to it)
        turned = half * math.cos(theta) + torch.linalg.cross(axis, half) * math.sin(theta)
        out.append(torch.stack([mid - turned, mid + turned]))
    return torch.stack(out)


def swap_rewards(path, min_turn, first_paid=False):
    task = Baoding()
    state = task.init_state(SHADOW, 1, torch.device("cpu"))
    state.min_turn.fill_(min_turn)
    task.set_parameter(state, "swap_first_paid", float(first_paid))
    rewards = []
    for pos in path:
        inputs = TaskInputs(
            ball_pos=pos[None],
            ball_vel=torch.zeros(1, 2, 3, dtype=torch.float64),
            ball_contact=torch.ones(1, 2, dtype=torch.bool),
        )
        rewards.append(float(task.step(state, inputs).reward_terms["swap"][0]))
    return rewards, int(state.swaps[0])


def test_the_task_pays_every_round_swap_one_swing_and_counts_all_swaps():
    # from a quarter turn before the balls' own targets (where roto's first swap is), 30 steps a half turn
    round_path = path_round_the_targets(np.linspace(0.5 * math.pi, 4.0 * math.pi, 106))  # swaps at 2, 3, 4 pi
    out, back = np.linspace(0.5 * math.pi, 2.0 * math.pi, 46), np.linspace(2.0 * math.pi, math.pi, 31)[1:]
    swing_path = path_round_the_targets(np.concatenate([out, back, back[::-1][1:], [2.0 * math.pi]]))
    for path in (round_path, swing_path):  # the benchmark: every swap paid
        rewards, swaps = swap_rewards(path, 0.0)
        assert swaps == 3 and sum(rewards) == 3 * SWAP_REWARD
    rewards, swaps = swap_rewards(round_path, 0.25)
    assert swaps == 3 and sum(rewards) == 3 * SWAP_REWARD
    rewards, swaps = swap_rewards(swing_path, 0.25)  # out (paid), back, out again: swaps both, paid neither
    assert swaps == 3 and sum(rewards) == SWAP_REWARD


def test_the_task_pays_a_replayed_starts_first_swap_only_with_first_paid():
    # a start a twentieth of a turn before a swap (as a replayed start is), then carried round
    path = path_round_the_targets(np.linspace(1.9 * math.pi, 4.0 * math.pi, 64))
    rewards, swaps = swap_rewards(path, 0.25)
    assert swaps == 3 and rewards[0] == 0.0 and sum(rewards) == 2 * SWAP_REWARD
    rewards, swaps = swap_rewards(path, 0.25, first_paid=True)
    assert swaps == 3 and rewards[0] == SWAP_REWARD and sum(rewards) == 3 * SWAP_REWARD


def test_an_env_sets_the_aid_from_its_config_and_evaluation_never_does():
    env = roto.make("baoding", robot="shadow", num_envs=2, seed=0, aids={"round_swaps": {"min_turn": 0.25}})
    assert float(env.task_state.min_turn) == 0.25 and float(env.task_state.first_paid) == 0.0
    aids = {"round_swaps": {"min_turn": 0.25, "first_paid": True}}
    assert float(roto.make("baoding", robot="shadow", num_envs=2, seed=0, aids=aids).task_state.first_paid) == 1.0
    assert float(roto.make("baoding", robot="shadow", num_envs=2, seed=0).task_state.min_turn) == 0.0
    settings = RunSpec(env=EnvConfig(task="baoding", aids={"round_swaps": {}}))  # a quarter turn by default
    assert (
        settings.eval_env_config(4).aids.round_swaps is None and settings.env_config().aids.round_swaps.min_turn == 0.25
    )


@pytest.mark.parametrize(
    ("task", "min_turn", "pattern"),
    [
        ("bounce", 0.25, r"aids.round_swaps applies to a task with swaps \(baoding\); task 'bounce' has none"),
        ("baoding", 0.75, r"aids.round_swaps.min_turn must be a number of turns in \[0, 0.5\], got 0.75"),
        ("baoding", -0.1, r"got -0.1"),
    ],
)
def test_bad_swap_min_turn_is_refused(task, min_turn, pattern):
    with pytest.raises(ValueError, match=pattern):
        EnvConfig(task=task, aids={"round_swaps": {"min_turn": min_turn}})


def test_a_first_paid_that_is_not_true_or_false_is_refused():
    with pytest.raises(ValueError, match=r"aids.round_swaps.first_paid must be true or false, got 'yes'"):
        EnvConfig(task="baoding", aids={"round_swaps": {"first_paid": "yes"}})

"""The turn-shaping training aid: a reward per turn the pair's net turning grows, given back as it
shrinks; a pair carried round earns it for every turn, a swing out and back earns nothing, either
way round counts, and with the aid off nothing is paid and the reward terms are the benchmark's."""

import math

import numpy as np
import pytest
import torch

import roto
from roto.envs.aids.episode_mean import EPISODE_WEIGHT
from roto.envs.aids.protocol import StepContext
from roto.envs.aids.turn_shaping import NarrowingTurnShaping
from roto.envs.config import EnvConfig
from roto.rl.run_spec import RunSpec
from roto.tasks.baoding import Baoding, geometry_of
from roto.tasks.base import TaskInputs
from roto.tasks.round_swaps import centre_offset, turn_pay_share, turn_shaping
from tests.tasks.test_round_swaps import SHADOW, path_round_the_targets


def test_the_shaping_pays_growth_of_the_net_turning_and_takes_it_back_as_it_shrinks():
    net = torch.tensor([0.0, 0.2, -0.2, 0.1], dtype=torch.float64)
    turn = torch.tensor([0.1, 0.1, -0.1, -0.3], dtype=torch.float64)
    reward, new_net = turn_shaping(net, turn, 20.0, math.inf, math.inf)
    assert new_net.tolist() == pytest.approx([0.1, 0.3, -0.3, -0.2])
    assert reward.tolist() == pytest.approx([2.0, 2.0, 2.0, 2.0])  # each magnitude grows by 0.1
    reward, _ = turn_shaping(torch.tensor([0.3]), torch.tensor([-0.1]), 20.0, math.inf, math.inf)
    assert float(reward[0]) == pytest.approx(-2.0)
    cap = torch.tensor([0.25, 0.25, 0.25, 0.25], dtype=torch.float64)  # bounded: growth past the cap is unpaid
    reward, _ = turn_shaping(net, turn, 20.0, cap, cap)
    assert reward.tolist() == pytest.approx([2.0, 1.0, 1.0, 2.0])
    reward, _ = turn_shaping(torch.tensor([0.3]), torch.tensor([0.0]), 20.0, 0.25, 0.75)  # a swap lifts the cap
    assert float(reward[0]) == pytest.approx(1.0)


def shaped_rewards(path, turn_reward, lead=None, near=None, soft=False):
    """(sum of the "turn" term over ``path``, the terms' names) of one Baoding world."""
    task = Baoding()
    state = task.init_state(SHADOW, 1, torch.device("cpu"))
    task.set_parameter(state, "turn_reward", turn_reward)
    if lead is not None:
        task.set_parameter(state, "turn_lead", lead)
    if near is not None:
        task.set_parameter(state, "turn_near", near)
    if soft:
        task.set_parameter(state, "turn_soft", 1.0)
    total, names = 0.0, set()
    for pos in path:
        inputs = TaskInputs(
            ball_pos=pos[None],
            ball_vel=torch.zeros(1, 2, 3, dtype=torch.float64),
            ball_contact=torch.ones(1, 2, dtype=torch.bool),
        )
        terms = task.step(state, inputs).reward_terms
        names |= set(terms)
        total += float(terms.get("turn", torch.zeros(1))[0])
    return total, names


def test_a_pair_carried_round_earns_per_turn_either_way_and_a_swing_earns_nothing():
    round_path = path_round_the_targets(np.linspace(0.5 * math.pi, 4.5 * math.pi, 121))  # two turns
    total, names = shaped_rewards(round_path, 20.0)
    assert total == pytest.approx(40.0) and names == {"swap", "distance", "turn"}
    total, _ = shaped_rewards(path_round_the_targets(np.linspace(4.5 * math.pi, 0.5 * math.pi, 121)), 20.0)
    assert total == pytest.approx(40.0)
    out, back = np.linspace(0.5 * math.pi, 2.0 * math.pi, 46), np.linspace(2.0 * math.pi, 0.5 * math.pi, 46)[1:]
    total, _ = shaped_rewards(path_round_the_targets(np.concatenate([out, back, out[1:], back])), 20.0)
    assert total == pytest.approx(0.0, abs=1e-9)
    total, names = shaped_rewards(round_path, 0.0)  # the benchmark: no turn term at all
    assert total == 0.0 and names == {"swap", "distance"}


def test_bounded_by_the_swaps_a_pair_spun_without_swapping_earns_only_the_lead():
    round_path = path_round_the_targets(np.linspace(0.5 * math.pi, 4.5 * math.pi, 121))  # two turns, 4 swaps
    total, _ = shaped_rewards(round_path, 20.0, lead=0.5)
    assert total == pytest.approx(40.0)  # the swaps keep pace: every turn paid
    # the same two turns about a point off the targets: the balls never latch, nothing swaps
    spun = round_path + torch.tensor([0.0, 0.05, 0.0], dtype=torch.float64)
    assert shaped_rewards(spun, 20.0)[0] == pytest.approx(40.0)  # unbounded: spinning pays
    assert shaped_rewards(spun, 20.0, lead=0.5)[0] == pytest.approx(10.0)  # bounded: half a turn


def test_paid_only_here_growth_elsewhere_is_unpaid_and_shrinking_is_charged_anywhere():
    net = torch.tensor([0.2, 0.2, 0.2, 0.2], dtype=torch.float64)
    turn = torch.tensor([0.1, -0.1, 0.1, -0.1], dtype=torch.float64)
    here = torch.tensor([True, True, False, False])
    reward, new_net = turn_shaping(net, turn, 20.0, math.inf, math.inf, here)
    assert reward.tolist() == pytest.approx([2.0, -2.0, 0.0, -2.0]) and new_net.tolist() == pytest.approx(
        [0.3, 0.1, 0.3, 0.1]
    )
    assert turn_shaping(net, turn, 20.0, math.inf, math.inf)[0].tolist() == pytest.approx([2.0, -2.0, 2.0, -2.0])


def test_the_pairs_centre_is_near_within_that_many_half_target_separations_of_their_midpoint():
    targets = torch.tensor(geometry_of(SHADOW).targets, dtype=torch.float64)
    half = float((targets[0] - targets[1]).norm()) / 2
    pair = path_round_the_targets([0.5 * math.pi])[0]  # centred on the targets' midpoint
    shifted = torch.stack([pair + torch.tensor([0.0, 0.0, k * half], dtype=torch.float64) for k in (0.0, 1.4, 1.6)])
    assert turn_pay_share(shifted, targets, 1.5).tolist() == [1.0, 1.0, 0.0]
    assert turn_pay_share(shifted, targets, 2.0).tolist() == [1.0, 1.0, 1.0]
    assert turn_pay_share(shifted.numpy(), targets.numpy(), 1.5).tolist() == [1.0, 1.0, 0.0]
    assert centre_offset(shifted, targets).tolist() == pytest.approx([0.0, 1.4, 1.6], abs=1e-9)
    assert centre_offset(shifted.numpy(), targets.numpy()).tolist() == pytest.approx([0.0, 1.4, 1.6], abs=1e-9)


def test_the_share_paid_is_whole_near_the_targets_and_beyond_nothing_or_falling_off_with_the_square():
    targets = torch.tensor(geometry_of(SHADOW).targets, dtype=torch.float64)
    half = float((targets[0] - targets[1]).norm()) / 2
    pair = path_round_the_targets([0.5 * math.pi])[0]
    offsets = (0.0, 1.4, 1.6, 3.0)
    shifted = torch.stack([pair + torch.tensor([0.0, 0.0, k * half], dtype=torch.float64) for k in offsets])
    assert turn_pay_share(shifted, targets, 1.5).tolist() == [1.0, 1.0, 0.0, 0.0]
    soft = [1.0, 1.0, (1.5 / 1.6) ** 2, 0.25]
    assert turn_pay_share(shifted, targets, 1.5, 1.0).tolist() == pytest.approx(soft)
    assert turn_pay_share(shifted.numpy(), targets.numpy(), 1.5, 1.0).tolist() == pytest.approx(soft)
    assert turn_pay_share(shifted, targets, 1e9, 1.0).tolist() == [1.0] * 4  # the task's default: anywhere
    assert turn_pay_share(shifted[:1], targets, 0.0, 1.0).tolist() == [0.0]  # near 0 at the midpoint: no 0 / 0
    net, turn = torch.tensor([0.3, 0.3]), torch.tensor([0.1, -0.1])
    reward, _ = turn_shaping(net, turn, 20.0, math.inf, math.inf, torch.tensor([0.25, 0.25]))
    assert reward.tolist() == pytest.approx([0.5, -2.0])  # growth paid at the share, shrinking in full


def test_paid_only_near_the_targets_turning_off_them_earns_nothing_and_no_loop_in_and_out_earns():
    round_path = path_round_the_targets(np.linspace(0.5 * math.pi, 4.5 * math.pi, 121))  # two turns
    assert shaped_rewards(round_path, 20.0, near=1.5)[0] == pytest.approx(40.0)  # round the targets: all paid
    spun = round_path + torch.tensor([0.0, 0.05, 0.0], dtype=torch.float64)  # 5 cm off: 2.5 half separations
    assert shaped_rewards(spun, 20.0)[0] == pytest.approx(40.0)
    assert shaped_rewards(spun, 20.0, near=1.5)[0] == pytest.approx(0.0)
    assert shaped_rewards(spun, 20.0, near=3.0)[0] == pytest.approx(40.0)
    half_turn = path_round_the_targets(np.linspace(0.5 * math.pi, 1.5 * math.pi, 31))
    off = torch.tensor([0.0, 0.05, 0.0], dtype=torch.float64)
    loop = torch.cat([half_turn, half_turn.flip(0) + off] * 3)  # out here, back off the targets, thrice
    assert shaped_rewards(loop, 20.0)[0] == pytest.approx(0.0, abs=1e-9)
    assert shaped_rewards(loop, 20.0, near=1.5)[0] == pytest.approx(0.0, abs=1e-9)
    reverse = torch.cat([half_turn + off, half_turn.flip(0)] * 3)  # out off the targets, back here
    assert shaped_rewards(reverse, 20.0, near=1.5)[0] == pytest.approx(-30.0)


def test_falling_off_turning_off_the_targets_earns_less_and_no_loop_in_and_out_earns():
    round_path = path_round_the_targets(np.linspace(0.5 * math.pi, 4.5 * math.pi, 121))  # two turns
    assert shaped_rewards(round_path, 20.0, near=1.5, soft=True)[0] == pytest.approx(40.0)
    spun = round_path + torch.tensor([0.0, 0.05, 0.0], dtype=torch.float64)  # about 2.5 half separations off
    targets = torch.tensor(geometry_of(SHADOW).targets, dtype=torch.float64)
    share = (1.5 / (0.05 / (float((targets[0] - targets[1]).norm()) / 2))) ** 2  # (near / offset)²
    assert shaped_rewards(spun, 20.0, near=1.5, soft=True)[0] == pytest.approx(40.0 * share)
    assert shaped_rewards(spun, 20.0, near=1.5, soft=True)[0] < shaped_rewards(spun, 20.0, near=2.0, soft=True)[0]
    half_turn = path_round_the_targets(np.linspace(0.5 * math.pi, 1.5 * math.pi, 31))
    off = torch.tensor([0.0, 0.05, 0.0], dtype=torch.float64)
    loop = torch.cat([half_turn, half_turn.flip(0) + off] * 3)  # out here, back off the targets, thrice
    assert shaped_rewards(loop, 20.0, near=1.5, soft=True)[0] == pytest.approx(0.0, abs=1e-9)
    reverse = torch.cat([half_turn + off, half_turn.flip(0)] * 3)  # out off the targets, back here
    assert shaped_rewards(reverse, 20.0, near=1.5, soft=True)[0] == pytest.approx(3 * (10.0 * share - 10.0))


def test_an_env_sets_the_aid_from_its_config_and_evaluation_never_does():
    env = roto.make("baoding", robot="shadow", num_envs=2, seed=0, aids={"turn_shaping": {"per_turn": 20.0}})
    assert float(env.task_state.turn_reward) == 20.0 and [type(a).__name__ for a in env.aids] == ["TurnShaping"]
    assert float(roto.make("baoding", robot="shadow", num_envs=2, seed=0).task_state.turn_reward) == 0.0
    settings = RunSpec(env=EnvConfig(task="baoding", aids={"turn_shaping": {"per_turn": 20.0}}))
    assert (
        settings.eval_env_config(4).aids.turn_shaping is None and settings.env_config().aids.turn_shaping.per_turn == 20
    )
    assert float(roto.make(**vars(settings.eval_env_config(2))).task_state.turn_reward) == 0.0
    bounded = roto.make("baoding", num_envs=1, aids={"turn_shaping": {"per_turn": 20.0, "lead": 0.5}})
    assert float(bounded.task_state.turn_lead) == 0.5 and float(env.task_state.turn_lead) == 1e9
    near = roto.make("baoding", num_envs=1, aids={"turn_shaping": {"per_turn": 20.0, "near": 1.5}})
    assert float(near.task_state.turn_near) == 1.5 and float(env.task_state.turn_near) == 1e9
    assert float(near.task_state.turn_soft) == 0.0
    soft = roto.make("baoding", num_envs=1, aids={"turn_shaping": {"per_turn": 20.0, "near": 1.5, "soft": True}})
    assert float(soft.task_state.turn_soft) == 1.0 and float(soft.task_state.turn_near) == 1.5


NARROWING = {"turn_shaping": {"per_turn": 20.0, "near": 1.0, "soft": True, "near_from": 3.0, "near_turns": 2.0}}


def test_a_narrowing_near_starts_wide_narrows_as_the_episodes_turn_the_pair_and_resumes_exactly():
    env = roto.make("baoding", robot="shadow", num_envs=4, seed=0, aids=NARROWING)
    shaping = env.aid(NarrowingTurnShaping)
    assert float(env.task_state.turn_near) == 3.0 and float(env.task_state.turn_soft) == 1.0
    env.reset()
    env.task_state.net_turn.copy_(torch.tensor([-1.0, 1.0, 9.0, 1.0], dtype=torch.float64))  # either way round
    ended = torch.tensor([True, True, False, True])  # the world still turning does not count
    shaping.observe(StepContext(None, None, None, env.task_state, None, None, ended))
    mean = 1.0 - (1.0 - EPISODE_WEIGHT) ** 3
    assert float(env.task_state.turn_near) == pytest.approx(1.0 + 2.0 * (1.0 - mean / 2.0))
    assert float(shaping.metrics()["train/turn_near"]) == pytest.approx(float(env.task_state.turn_near))
    other = roto.make("baoding", robot="shadow", num_envs=4, seed=5, aids=NARROWING)
    other.load_state_dict(env.state_dict())
    assert torch.equal(other.aid(NarrowingTurnShaping).near.mean, shaping.near.mean)
    assert torch.equal(other.task_state.turn_near, env.task_state.turn_near)
    env.task_state.net_turn.fill_(2.0)
    for _ in range(600):  # episodes that turn the pair near_turns: near itself
        shaping.observe(StepContext(None, None, None, env.task_state, None, None, torch.ones(4, dtype=torch.bool)))
    assert float(env.task_state.turn_near) == pytest.approx(1.0, abs=1e-6)
    fixed = roto.make(
        "baoding", robot="shadow", num_envs=4, seed=0, aids={"turn_shaping": {"per_turn": 20.0, "near": 1.0}}
    )
    assert fixed.aid(NarrowingTurnShaping) is None and [type(a).__name__ for a in fixed.aids] == ["TurnShaping"]


@pytest.mark.parametrize(
    ("task", "per_turn", "pattern"),
    [
        ("bounce", 20.0, r"aids.turn_shaping applies to a task with a ball pair \(baoding\); task 'bounce' has none"),
        ("baoding", -1.0, r"aids.turn_shaping.per_turn must be a reward per turn in \[0, 1000\], got -1.0"),
        ("baoding", float("nan"), r"got nan"),
        ("baoding", "20", r"got '20'"),
        ("baoding", {"lead": -1.0}, r"aids.turn_shaping.lead must be a number of turns.*got -1.0"),
        ("baoding", {"near": -1.5}, r"aids.turn_shaping.near must be a number of half target separations.*got -1.5"),
        ("baoding", {"near": "far"}, r"aids.turn_shaping.near must be .*got 'far'"),
        ("baoding", {"near": 1.5, "soft": "yes"}, r"aids.turn_shaping.soft must be true or false, got 'yes'"),
        ("baoding", {"soft": True}, r"aids.turn_shaping.soft needs aids.turn_shaping.near .*got near=None"),
        ("baoding", {"near_from": 3.0}, r"aids.turn_shaping.near_from needs aids.turn_shaping.near .*got near=None"),
        ("baoding", {"near": 1.0, "near_from": 0.5}, r"aids.turn_shaping.near_from must be .* in \[1, 100\], got 0.5"),
        ("baoding", {"near": 1.0, "near_turns": 0}, r"aids.turn_shaping.near_turns must be net turns .*got 0"),
    ],
)
def test_bad_turn_reward_is_refused(task, per_turn, pattern):
    with pytest.raises(ValueError, match=pattern):
        settings = per_turn if isinstance(per_turn, dict) else {"per_turn": per_turn}
        EnvConfig(task=task, aids={"turn_shaping": settings})

"""The round-swaps aid: from the first step, or armed part way (``after``): every swap paid until
the training episodes reach ``after`` rotations, a swing out and back paid once an episode from
then on, for good; its state is saved with the env, and bad settings are refused."""

import pytest
import torch

import roto
from roto.envs.aids.episode_mean import EPISODE_WEIGHT
from roto.envs.aids.protocol import StepContext
from roto.envs.aids.round_swaps import ArmedRoundSwaps, RoundSwaps
from roto.envs.config import EnvConfig
from roto.tasks.round_swaps import paid_swaps

ARMED = {"round_swaps": {"min_turn": 0.25, "first_paid": True, "after": 2.0}}


def end_episodes(env, rotations: float, worlds: int = 4) -> None:
    """Show the armed aid one step on which ``worlds`` episodes end with ``rotations`` each."""
    metric = torch.full((env.num_envs,), rotations, dtype=torch.float64)
    done = torch.arange(env.num_envs) < worlds
    env.aid(ArmedRoundSwaps).observe(StepContext(None, None, None, env.task_state, metric, None, done))


def swing_paid(task_state) -> list[bool]:
    """Which swaps of a swing out (+0.1 turn) and back (-0.1 turn) the task's parameters pay."""
    turned, direction, paid = torch.zeros(1), torch.zeros(1), []
    for turn in (0.1, -0.1, 0.1, -0.1):
        swap = torch.ones(1, dtype=torch.bool)
        now, turned, direction = paid_swaps(swap, turned + turn, direction, task_state.min_turn, task_state.first_paid)
        paid.append(bool(now))
    return paid


def test_armed_round_swaps_pay_every_swap_until_the_episodes_reach_after_then_only_round_ones():
    env = roto.make("baoding", robot="shadow", num_envs=4, seed=0, aids=ARMED)
    aid = env.aid(ArmedRoundSwaps)
    assert aid is not None and env.aid(RoundSwaps) is None
    assert float(env.task_state.min_turn) == 0.0 and float(env.task_state.first_paid) == 1.0
    assert swing_paid(env.task_state) == [True, True, True, True]
    end_episodes(env, 1.0)
    assert float(aid.mean) == pytest.approx(1.0 - (1.0 - EPISODE_WEIGHT) ** 4)
    assert float(env.task_state.min_turn) == 0.0 and float(env.aid_metrics()["train/round_swaps_armed"]) == 0.0
    for _ in range(400):  # episodes of 3 rotations: the running mean passes 2
        end_episodes(env, 3.0)
    assert float(env.task_state.min_turn) == 0.25 and float(env.aid_metrics()["train/round_swaps_armed"]) == 1.0
    assert swing_paid(env.task_state) == [True, False, False, False]  # the first swap only (first_paid)
    for _ in range(400):  # the episodes fall back: round swaps hold
        end_episodes(env, 0.0)
    assert float(aid.mean) < 2.0 and float(env.task_state.min_turn) == 0.25


def test_the_armed_aid_resumes_exactly_and_round_swaps_without_after_hold_from_the_start():
    env = roto.make("baoding", robot="shadow", num_envs=4, seed=0, aids=ARMED)
    for _ in range(400):
        end_episodes(env, 3.0)
    other = roto.make("baoding", robot="shadow", num_envs=4, seed=3, aids=ARMED)
    assert float(other.task_state.min_turn) == 0.0
    other.load_state_dict(env.state_dict())
    assert torch.equal(other.aid(ArmedRoundSwaps).mean, env.aid(ArmedRoundSwaps).mean)
    assert bool(other.aid(ArmedRoundSwaps).armed) and float(other.task_state.min_turn) == 0.25
    plain = roto.make("baoding", robot="shadow", num_envs=4, seed=0, aids={"round_swaps": {"min_turn": 0.25}})
    assert plain.aid(ArmedRoundSwaps) is None and plain.aid(RoundSwaps) is not None
    assert float(plain.task_state.min_turn) == 0.25 and swing_paid(plain.task_state) == [False] * 4


@pytest.mark.parametrize(
    ("after", "pattern"),
    [
        (0.0, r"aids.round_swaps.after must be rotations per episode \(or null: from the start\).*got 0.0"),
        ("2", r"aids.round_swaps.after must be rotations per episode.*got '2'"),
        (True, r"aids.round_swaps.after must be rotations per episode.*got True"),
    ],
)
def test_bad_after_is_refused_naming_it(after, pattern):
    with pytest.raises(ValueError, match=pattern):
        EnvConfig(task="baoding", aids={"round_swaps": {"min_turn": 0.25, "after": after}})

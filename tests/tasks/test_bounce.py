import torch

from roto.robots import get_robot
from roto.tasks.base import TaskInputs
from roto.tasks.bounce import Bounce, bounce_counter


def _count(sequence: list[int]) -> list[bool]:
    """Run the counter on one env's contact sequence; return the bounce flags."""
    prev = torch.tensor([False])
    waiting = torch.tensor([False])
    gap = torch.tensor([0])
    out = []
    for c in sequence:
        contact = torch.tensor([bool(c)])
        bounce, waiting, gap = bounce_counter(contact, prev, waiting, gap)
        prev = contact
        out.append(bool(bounce))
    return out


def test_first_touchdown_is_not_a_bounce():
    assert _count([0] * 10 + [1, 1, 1]) == [False] * 13


def test_bounce_after_five_steps_in_the_air():
    flags = _count([0] * 10 + [1, 1] + [0] * 5 + [1, 1])
    assert flags.index(True) == 17 and sum(flags) == 1


def test_four_steps_in_the_air_is_too_short_but_waiting_persists():
    flags = _count([0] * 10 + [1] + [0] * 4 + [1] + [0] * 5 + [1])
    assert sum(flags) == 1 and flags[-1]


def test_two_bounces():
    seq = [0] * 8 + [1] + ([0] * 6 + [1]) * 2
    assert sum(_count(seq)) == 2


def _inputs(z: float, contact: bool, x: float = 0.0) -> TaskInputs:
    return TaskInputs(
        ball_pos=torch.tensor([[[x, 0.0, z]]], dtype=torch.float64),
        ball_vel=torch.zeros(1, 1, 3, dtype=torch.float64),
        ball_contact=torch.tensor([[contact]]),
    )


def test_reward_is_ten_per_bounce_and_counted():
    task = Bounce()
    state = task.init_state(get_robot("shadow"), 1, torch.device("cpu"))
    rewards = []
    for contact in [0] * 6 + [1] + [0] * 6 + [1]:
        result = task.step(state, _inputs(0.05, bool(contact)))
        rewards.append(float(result.reward_terms["bounce"][0]))
    assert rewards.count(10.0) == 1 and rewards[-1] == 10.0
    assert task.metrics(state)["bounces"].tolist() == [1.0]


def test_terminations():
    task = Bounce()
    state = task.init_state(get_robot("shadow"), 1, torch.device("cpu"))
    assert not task.step(state, _inputs(-0.19, False)).terminated[0]
    assert task.step(state, _inputs(-0.21, False)).terminated[0]
    assert task.step(state, _inputs(0.05, False, x=0.21)).terminated[0]
    assert not task.step(state, _inputs(0.05, False, x=0.19)).terminated[0]


def test_reset_clears_counters_and_spawns_above_palm():
    task = Bounce()
    state = task.init_state(get_robot("shadow"), 3, torch.device("cpu"))
    state.bounces[:] = 4
    state.waiting[:] = True
    task.reset(state, torch.tensor([True, False, True]))
    pos = task.initial_ball_positions(state, 2, torch.Generator().manual_seed(0))
    assert state.bounces.tolist() == [0, 4, 0] and state.waiting.tolist() == [False, True, False]
    assert pos.shape == (2, 1, 3)
    assert torch.all((pos[..., 2] - 0.10).abs() <= 0.01) and torch.all(pos[..., :2].abs() <= 0.01)

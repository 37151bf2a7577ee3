import numpy as np
import pytest
import torch

from roto.envs.config import EnvConfig
from roto.eval.bounce_rhythm import record_rhythm, rhythm
from roto.rl.networks import ActorCritic
from roto.rl.run_spec import RunSpec
from roto.tasks.bounce import MIN_FLIGHT_STEPS, bounce_counter


def counted(contact: np.ndarray) -> np.ndarray:
    """(T, B) bool: the task's own bounce rule run over a contact record."""
    num_envs = contact.shape[1]
    prev = torch.zeros(num_envs, dtype=torch.bool)
    waiting = torch.zeros(num_envs, dtype=torch.bool)
    flight = torch.zeros(num_envs, dtype=torch.int64)
    out = []
    for row in torch.from_numpy(contact):
        bounce, waiting, flight = bounce_counter(row, prev, waiting, flight)
        prev = row
        out.append(bounce.numpy())
    return np.stack(out)


def test_a_regular_rhythm_splits_into_touch_and_flight():
    # spawn fall of 10 steps, then touches of 2 steps and flights of 6: a bounce every 8 steps
    pattern = [False] * 10 + ([True] * 2 + [False] * 6) * 20
    contact = np.array(pattern)[:, None].repeat(3, axis=1)
    height = np.where(contact, 0.0, 0.01)
    figures = rhythm(contact, counted(contact), height, np.full(3, len(pattern)))
    assert figures["bounces"] == 19  # the spawn's touchdown is not a bounce
    assert figures["period_steps"] == 8
    assert figures["touch_steps"] == 2
    assert figures["flight_steps"] == 6
    assert figures["apex_cm"] == pytest.approx(1.0)
    assert figures["min_flight_share"] == 0.0
    assert figures["short_touches"] == 0.0


def test_short_flights_do_not_count_and_lengths_cut_the_record():
    flight = MIN_FLIGHT_STEPS
    one = [False] * 4 + [True] + [False] * flight + [True] + [False] * 2 + [True] + [False] * flight + [True]
    contact = np.array(one + [False] * 5 + [True])[:, None]
    figures = rhythm(contact, counted(contact), np.zeros(contact.shape), np.array([len(one)]))
    assert figures["bounces"] == 2
    assert figures["short_touches"] == 1  # the touch after a 2-step flight
    assert figures["min_flight_share"] == 1.0
    assert figures["period_steps"] == len(one) - 1 - (4 + 1 + flight)


def test_random_records_agree_with_the_bounce_rule():
    rng = np.random.default_rng(0)
    contact = rng.random((300, 8)) < 0.3
    bounce = counted(contact)
    figures = rhythm(contact, bounce, rng.random(contact.shape), np.full(8, 300))
    touches = sum(int(np.sum(np.diff(np.concatenate([[0], c.astype(int)])) == 1)) for c in contact.T)
    first_touch_counts = sum(int(bounce[np.argmax(c), b]) for b, c in enumerate(contact.T))
    assert first_touch_counts == 0
    assert figures["bounces"] + figures["short_touches"] + 1 == pytest.approx(touches / 8)
    assert figures["flight_steps"] >= MIN_FLIGHT_STEPS


def test_recorded_episodes_match_the_envs_own_count():
    settings = RunSpec(env=EnvConfig(task="bounce", robot="shadow", num_envs=2, threads=1, episode_steps=60))
    policy = ActorCritic({"tactile": 68, "proprio": 320}, 20, actor_groups=("tactile", "proprio"), encoder=(16,))
    contact, bounce, height, lengths = record_rhythm(policy, settings, envs=2, seed=3)
    assert contact.shape == bounce.shape == height.shape == (60, 2)
    assert lengths.shape == (2,) and (lengths <= 60).all()
    assert contact.any()  # the ball lands on the hand within the second
    inside = np.arange(60)[:, None] < lengths  # each env's first episode
    assert np.array_equal(bounce & inside, counted(contact) & inside)
    assert (height[:5] > 0.05).all()  # the ball spawns 10 cm above the palm and starts falling


@pytest.mark.parametrize(("task", "envs", "named"), [("baoding", 2, "'baoding'"), ("bounce", 0, "got 0")])
def test_a_run_of_another_task_or_no_envs_is_refused_by_name(task, envs, named):
    settings = RunSpec(env=EnvConfig(task=task, robot="shadow", num_envs=2, threads=1))
    policy = ActorCritic({"tactile": 68, "proprio": 320}, 20, actor_groups=("tactile", "proprio"), encoder=(16,))
    with pytest.raises(ValueError, match=named):
        record_rhythm(policy, settings, envs=envs)

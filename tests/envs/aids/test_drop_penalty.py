"""The drop penalty: a Bounce training episode that ends with the ball lost is charged, nothing else
changes, the env resumes with it, evaluation never carries it, and bad settings are refused."""

import pytest
import torch

import roto
from roto.envs.aids.drop_penalty import DropPenalty
from roto.envs.config import EnvConfig
from roto.rl.run_spec import RunSpec

PENALTY = {"drop_penalty": {"per_drop": 7.5}}


def rollout(env, steps=240, seed=3):
    """(rewards, terminated, observations) of ``steps`` uniform random actions, each stacked (steps, B, ...)."""
    generator = torch.Generator().manual_seed(seed)
    env.reset()
    rewards, ends, observations = [], [], []
    for _ in range(steps):
        action = torch.rand(env.num_envs, env.num_actions, generator=generator) * 2 - 1
        obs, reward, terminated, _truncated, _info = env.step(action)
        rewards.append(reward.clone())
        ends.append(terminated.clone())
        observations.append(torch.cat([obs[group] for group in sorted(obs)], dim=-1))
    return torch.stack(rewards), torch.stack(ends), torch.stack(observations)


def test_a_lost_ball_is_charged_on_its_last_step_and_nothing_else_changes():
    """Against the plain env on the same seed and actions: the same physics and ends, each episode
    that ends with the ball lost charged 7.5 on that step, every other reward the same."""
    charged = roto.make("bounce", robot="allegro", num_envs=16, seed=0, aids=PENALTY)
    plain = roto.make("bounce", robot="allegro", num_envs=16, seed=0)
    assert float(charged.task_state.drop_penalty) == 7.5 and float(plain.task_state.drop_penalty) == 0.0
    rewards, ends, observations = rollout(charged)
    plain_rewards, plain_ends, plain_observations = rollout(plain)
    assert torch.equal(ends, plain_ends) and torch.equal(observations, plain_observations)
    assert ends.sum() > 0  # some balls were lost
    assert torch.equal(rewards, plain_rewards - 7.5 * ends.to(rewards.dtype))


def test_the_env_resumes_with_its_penalty_and_a_plain_env_has_no_aid():
    env = roto.make("bounce", robot="shadow", num_envs=4, seed=0, aids=PENALTY)
    assert env.aid(DropPenalty) is not None
    other = roto.make("bounce", robot="shadow", num_envs=4, seed=1, aids=PENALTY)
    other.task.set_parameter(other.task_state, "drop_penalty", 0.0)
    other.load_state_dict(env.state_dict())
    assert float(other.task_state.drop_penalty) == 7.5
    plain = roto.make("bounce", robot="shadow", num_envs=4, seed=0)
    assert plain.aid(DropPenalty) is None


def test_evaluation_envs_charge_nothing():
    settings = RunSpec(env=EnvConfig(task="bounce", aids=PENALTY))
    assert settings.eval_env_config(4).aids.drop_penalty is None
    assert settings.cpu_env_config(1).aids.drop_penalty is None
    assert settings.env_config().aids.drop_penalty.per_drop == 7.5


@pytest.mark.parametrize(
    ("task", "settings", "pattern"),
    [
        ("baoding", {"per_drop": 10.0}, r"to a task with a ball to lose \(bounce\).*'baoding' has none"),
        ("bounce", {"per_drop": -1.0}, r"per_drop must be a reward charged per lost ball in \[0, 1000\], got -1.0"),
        ("bounce", {"per_drop": "ten"}, r"aids.drop_penalty.per_drop .*got 'ten'"),
        ("bounce", {"per_lost": 10.0}, r"unknown setting\(s\) \['per_lost'\] of aids.drop_penalty; valid settings"),
    ],
)
def test_bad_drop_penalty_settings_are_refused(task, settings, pattern):
    with pytest.raises(ValueError, match=pattern):
        EnvConfig(task=task, aids={"drop_penalty": settings})

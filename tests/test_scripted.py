import itertools

import pytest
import torch

from roto.scripted import HOLD, STRIKE, WIND_UP, ScriptedBounce
from tests.conftest import make_env


def test_policy_needs_the_ball_state():
    env = make_env(obs_mode="blind")
    with pytest.raises(ValueError, match="obs_mode='state'"):
        ScriptedBounce(env)


def test_phases_cycle_hold_wind_up_strike():
    env = make_env(obs_mode="state", num_envs=1)
    policy = ScriptedBounce(env)
    obs, _ = env.reset(seed=0)
    phases = []
    for _ in range(240):
        action = policy(obs)
        assert action.shape == (1, env.num_actions) and action.abs().max() <= 1.0
        obs, *_ = env.step(action)
        phases.append(int(policy.phase[0]))
    s = policy.script
    runs = [(p, len(list(g))) for p, g in itertools.groupby(phases)]
    assert [p for p, _ in runs[:4]] == [HOLD, WIND_UP, STRIKE, HOLD]
    assert all(n == s.wind_up_steps for p, n in runs[1:-1] if p == WIND_UP)
    assert all(n == s.strike_steps for p, n in runs[1:-1] if p == STRIKE)
    assert int(env.task_state.bounces[0]) >= 3
    policy.reset(torch.tensor([True]))
    assert int(policy.phase[0]) == HOLD

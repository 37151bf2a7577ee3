"""Predictive sampling: its splines against numpy's interpolation, its choice, and its predictions
against the env's own step (the planner rolls out the true dynamics)."""

import numpy as np
import pytest
import torch

from roto.envs.control import target_to_action
from roto.reference.predictive_sampling import PredictiveSampling, SamplingConfig, shifted_knots, spline
from roto.registry import make


def interp_reference(knots: np.ndarray, times: np.ndarray, horizon: int) -> np.ndarray:
    """The slow reference: per joint, np.interp over the knots' times, held beyond the last knot."""
    knot_times = np.linspace(0.0, horizon - 1.0, len(knots))
    return np.stack([np.interp(times, knot_times, knots[:, j]) for j in range(knots.shape[1])], axis=-1)


@pytest.mark.parametrize(("knots", "horizon"), [(2, 5), (4, 30), (5, 9), (3, 3)])
def test_spline_matches_linear_interpolation(knots, horizon):
    values = np.random.default_rng(0).normal(size=(3, knots, 4))
    got = spline(values, horizon)
    assert got.shape == (3, horizon, 4)
    for n in range(3):
        np.testing.assert_allclose(got[n], interp_reference(values[n], np.arange(horizon), horizon), atol=1e-12)


@pytest.mark.parametrize("shift", [1, 3, 40])
def test_shifted_knots_advance_the_spline_in_time(shift):
    horizon, values = 30, np.random.default_rng(1).normal(size=(4, 6))
    knot_times = np.linspace(0.0, horizon - 1.0, 4)
    expected = interp_reference(values, knot_times + shift, horizon)  # np.interp holds the last value
    np.testing.assert_allclose(shifted_knots(values, horizon, shift), expected, atol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"samples": 0}, r"samples must be an integer >= 1, got 0"),
        ({"knots": 1}, r"knots must be in \[2, horizon=30\], got 1"),
        ({"horizon": 3, "knots": 4}, r"knots must be in \[2, horizon=3\], got 4"),
        ({"sigma": 0.0}, r"sigma must be > 0, got 0.0"),
    ],
)
def test_bad_settings_are_refused(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        SamplingConfig(**kwargs)


@pytest.fixture
def env():
    env = make("baoding", robot="shadow", num_envs=1, seed=2)
    env.reset()
    yield env
    env.close()


def planner_for(env, **kwargs) -> PredictiveSampling:
    lo, hi = env.indices.ctrl_lo.numpy(), env.indices.ctrl_hi.numpy()
    return PredictiveSampling(env.model, lo, hi, SamplingConfig(threads=1, **kwargs))


def test_the_plan_is_the_cheapest_sample_within_the_joint_limits(env):
    planner = planner_for(env, samples=16, horizon=6, knots=2)
    hold = env.joint_targets[0].numpy()
    planner.reset(hold)
    j = int(np.argmax(np.minimum(planner.hi - hold, hold - planner.lo)))  # a joint with room both ways
    seen = []

    def cost(states, targets):
        seen.append(targets[:, 0, j].copy())
        return -targets[:, 0, j]  # prefer joint j's first target high

    chosen = planner.plan(env.backend.physics_state()[0], cost)
    assert chosen[j] == seen[0].max() and seen[0][0] == hold[j]  # sample 0 is the nominal plan
    assert chosen[j] > hold[j]
    assert np.all(chosen >= planner.lo) and np.all(chosen <= planner.hi)
    planner.close()


def test_a_rollout_predicts_the_env_s_next_state(env):
    """The first control step of the nominal plan (hold) is the env's own next physics state."""
    planner = planner_for(env, samples=1, horizon=5, knots=2)
    planner.reset(env.joint_targets[0].numpy())
    predicted = []

    def cost(states, targets):
        predicted.append(states[0, 0].copy())
        return np.zeros(len(states))

    target = planner.plan(env.backend.physics_state()[0], cost)
    action = target_to_action(torch.from_numpy(target)[None], env.indices.ctrl_lo, env.indices.ctrl_hi)
    env.step(action)
    np.testing.assert_allclose(env.backend.physics_state()[0], predicted[0], atol=1e-6)
    planner.close()


def test_plan_before_reset_is_a_clear_error(env):
    planner = planner_for(env, samples=2, horizon=4, knots=2)
    with pytest.raises(RuntimeError, match=r"call reset\(target\) before plan\(\)"):
        planner.plan(env.backend.physics_state()[0], lambda s, t: np.zeros(len(s)))
    planner.close()

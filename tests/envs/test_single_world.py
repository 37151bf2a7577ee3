"""The one-world fast step (numpy glue) against its reference, ``RotoEnv.step`` itself."""

import numpy as np
import pytest
import torch

from roto.envs.single_world import SingleWorldStep, _finite, single_world_result, supports_single_world_step
from roto.registry import list_envs, make


def assert_same_step(fast, reference):
    obs, reward, terminated, truncated, info = fast
    ref_obs, ref_reward, ref_terminated, ref_truncated, ref_info = reference
    assert obs.keys() == ref_obs.keys()
    for name in obs:
        assert obs[name].dtype == ref_obs[name].dtype == np.float32
        np.testing.assert_array_equal(obs[name], ref_obs[name], err_msg=name)
    assert (reward, terminated, truncated) == (ref_reward, ref_terminated, ref_truncated)
    assert type(reward) is float and type(terminated) is bool and type(truncated) is bool
    assert info == ref_info


def assert_same_state(a, b):
    def same(x, y):
        if isinstance(x, dict):
            assert x.keys() == y.keys()
            for key in x:
                same(x[key], y[key])
        elif isinstance(x, torch.Tensor):
            assert torch.equal(x, y)
        else:
            assert x == y

    same(a.state_dict(), b.state_dict())


def run_both(task, robot, steps, seed=0, **config):
    fast_env = make(task, robot=robot, num_envs=1, seed=seed, **config)
    reference_env = make(task, robot=robot, num_envs=1, seed=seed, **config)
    fast = SingleWorldStep(fast_env)
    fast_env.reset(seed=seed)
    reference_env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    episodes = 0
    for _ in range(steps):
        action = rng.uniform(-1.3, 1.3, fast_env.num_actions).astype(np.float32)  # some beyond the limits
        result = fast.step(action)
        assert_same_step(result, single_world_result(*reference_env.step(torch.from_numpy(action)[None])))
        episodes += result[2] or result[3]
    assert_same_state(fast_env, reference_env)
    return episodes


@pytest.mark.parametrize(("task", "robot"), list_envs())
def test_fast_step_matches_the_env_step_in_every_pair(task, robot):
    assert run_both(task, robot, 250, obs_mode="state", episode_steps=100) >= 2  # ends and resets compared too


@pytest.mark.parametrize("obs_mode", ["blind", "proprio"])
def test_fast_step_matches_in_every_obs_mode(obs_mode):
    run_both("bounce", "allegro", 120, obs_mode=obs_mode)


def test_fast_step_matches_with_smoothing_short_episodes_and_other_stacks():
    episodes = run_both("baoding", "shadow", 150, action_smoothing=0.4, episode_steps=40, frame_stack=2)
    assert episodes >= 3  # time-outs


def test_fast_and_env_steps_can_alternate():
    env = make("bounce", robot="shadow", num_envs=1, seed=1)
    reference_env = make("bounce", robot="shadow", num_envs=1, seed=1)
    fast = SingleWorldStep(env)
    env.reset(seed=1)
    reference_env.reset(seed=1)
    for t in range(60):
        action = np.full(env.num_actions, 0.3 * np.sin(t), dtype=np.float64)
        tensor = torch.from_numpy(action)[None]
        expected = single_world_result(*reference_env.step(tensor))
        got = fast.step(action) if t % 3 else single_world_result(*env.step(tensor))
        assert_same_step(got, expected)
    assert_same_state(env, reference_env)


def test_bad_actions_get_the_envs_errors():
    env = make("bounce", robot="shadow", num_envs=1)
    fast = SingleWorldStep(env)
    with pytest.raises(RuntimeError, match="call reset"):
        fast.step(np.zeros(env.num_actions, dtype=np.float32))
    env.reset()
    with pytest.raises(TypeError, match="not floating point"):
        fast.step(np.zeros(env.num_actions, dtype=np.int64))
    with pytest.raises(ValueError, match="action shape"):
        fast.step(np.zeros(env.num_actions + 1, dtype=np.float32))
    nan = np.zeros(env.num_actions, dtype=np.float32)
    nan[3] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        fast.step(nan)


def test_only_one_cpu_world_is_supported():
    batched = make("bounce", robot="shadow", num_envs=2)
    assert not supports_single_world_step(batched)
    with pytest.raises(ValueError, match="num_envs=2"):
        SingleWorldStep(batched)
    assert supports_single_world_step(make("bounce", robot="shadow", num_envs=1))


def test_non_finite_frame_values_become_zero_in_place_as_nan_to_num_makes_them():
    values = np.array([[1.5, np.nan, np.inf, -np.inf, -2.0]], dtype=np.float32)
    expected = torch.from_numpy(values.copy()).nan_to_num_(nan=0.0, posinf=0.0, neginf=0.0).numpy()
    assert _finite(values) is values
    np.testing.assert_array_equal(values, expected)
    assert _finite(values) is values and values.tolist() == [[1.5, 0.0, 0.0, 0.0, -2.0]]

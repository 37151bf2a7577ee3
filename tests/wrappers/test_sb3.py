"""The Stable-Baselines3 adapter, proven by SB3's own PPO and against the batched env it wraps."""

import numpy as np
import pytest
import torch

import roto
from tests.conftest import require_extra

require_extra("stable_baselines3", "sb3")  # installed by `make test`
import stable_baselines3 as sb3  # noqa: E402
from stable_baselines3.common.vec_env import VecMonitor  # noqa: E402

from roto.wrappers.sb3 import Sb3VecEnv  # noqa: E402


def test_sb3_ppo_trains_on_the_batched_env():
    venv = VecMonitor(Sb3VecEnv(roto.make("bounce", num_envs=8, seed=0)))
    model = sb3.PPO("MultiInputPolicy", venv, n_steps=16, batch_size=64, n_epochs=2, seed=0, device="cpu")
    before = [p.detach().clone() for p in model.policy.parameters()]
    model.learn(total_timesteps=256)
    assert model.num_timesteps == 256
    after = list(model.policy.parameters())
    assert all(torch.isfinite(p).all() for p in after)
    assert any(not torch.equal(a, b) for a, b in zip(after, before, strict=True)), "PPO changed nothing"
    assert np.isfinite(model.logger.name_to_value["train/loss"])
    venv.close()


def test_finished_worlds_report_their_last_observation_and_time_limit():
    env = roto.make("bounce", num_envs=3, seed=1, episode_steps=4)
    venv = Sb3VecEnv(env)
    venv.seed(5)
    obs = venv.reset()
    assert set(obs) == set(env.observation_space.spaces) and obs["proprio"].shape == (3, 4 * env.frame_sizes["proprio"])
    hold = np.repeat(env.hold_action().numpy(), 3, axis=0)
    for _ in range(3):
        obs, reward, done, infos = venv.step(hold)
        assert not done.any() and infos == [{}, {}, {}]
    reference = roto.make("bounce", num_envs=3, seed=1, episode_steps=4)
    reference.reset(seed=5)
    for _ in range(3):
        reference.step(reference.hold_action().repeat(3, 1))
    expected = reference.step(reference.hold_action().repeat(3, 1))
    obs, reward, done, infos = venv.step(hold)
    assert done.all() and all(info["TimeLimit.truncated"] for info in infos)
    for world in range(3):
        for name, value in infos[world]["terminal_observation"].items():
            assert np.array_equal(value, expected[4]["final_obs"][name][world].numpy())
    assert np.array_equal(obs["proprio"], expected[0]["proprio"].numpy())
    assert np.array_equal(reward, expected[1].numpy())


def test_per_world_attribute_writes_are_a_clear_error():
    venv = Sb3VecEnv(roto.make("bounce", num_envs=2))
    assert venv.get_attr("num_actions") == [venv.env.num_actions] * 2
    with pytest.raises(AttributeError, match="roto's 2 worlds share one env"):
        venv.set_attr("seed", 3)


def test_sb3_env_checker_accepts_the_single_gymnasium_env():
    import gymnasium
    from stable_baselines3.common.env_checker import check_env

    env = gymnasium.make("roto/Bounce-Shadow-v0")
    check_env(env.unwrapped, warn=True)
    env.close()


def test_a_gymnasium_env_is_refused_naming_the_adapter():
    import gymnasium

    with pytest.raises(TypeError, match=r"^Sb3VecEnv wraps a batched roto env"):
        Sb3VecEnv(gymnasium.make("roto/Bounce-Shadow-v0"))

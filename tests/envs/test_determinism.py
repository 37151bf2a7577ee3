import pytest
import torch

from roto.registry import list_envs
from tests.conftest import make_env


def _rollout(seed: int, task: str, steps: int = 200, robot: str = "shadow"):
    env = make_env(task, robot=robot, num_envs=4, seed=seed, obs_mode="state")
    gen = torch.Generator().manual_seed(123)
    obs, _ = env.reset()
    observations, rewards = [obs], []
    for _ in range(steps):
        obs, reward, *_ = env.step(torch.rand(4, env.num_actions, generator=gen) * 2 - 1)
        observations.append(obs)
        rewards.append(reward)
    env.close()
    return observations, torch.stack(rewards)


@pytest.mark.parametrize(("task", "robot"), list_envs())
def test_same_seed_is_bit_identical_over_200_steps(task, robot):
    obs_a, rew_a = _rollout(0, task, robot=robot)
    obs_b, rew_b = _rollout(0, task, robot=robot)
    assert torch.equal(rew_a, rew_b)
    for a, b in zip(obs_a, obs_b, strict=True):
        for name in a:
            assert torch.equal(a[name], b[name])


def test_different_seeds_differ():
    obs_a, _ = _rollout(0, "bounce", steps=5)
    obs_b, _ = _rollout(1, "bounce", steps=5)
    assert not torch.equal(obs_a[0]["privileged"], obs_b[0]["privileged"])


def test_threads_do_not_change_results():
    gen = torch.Generator().manual_seed(0)
    actions = torch.rand(50, 8, 20, generator=gen) * 2 - 1
    results = []
    for threads in (1, 2):
        env = make_env("baoding", num_envs=8, threads=threads)
        env.reset()
        results.append(torch.stack([env.step(a)[0]["proprio"] for a in actions]))
        env.close()
    assert torch.equal(results[0], results[1])

import torch

from roto.envs.config import EnvConfig
from roto.envs.episodes import first_episodes
from tests.rl.toy_env import EPISODE_STEPS, ToyEnv


def test_keeps_each_envs_first_episodes_and_reports_finishes():
    env = ToyEnv(EnvConfig(task="bounce", num_envs=3, seed=0))
    obs, _ = env.reset(seed=0)
    calls = []
    steps = []

    def act(o):
        steps.append(1)
        return o["proprio"][:, -2:]  # the exact target: reward 1 per step

    result = first_episodes(env, act, obs, episodes_per_env=2, on_done=calls.append)
    assert set(result) == {"return", "length", "hits"}
    assert result["return"].shape == (3, 2)
    assert torch.equal(result["length"], torch.full((3, 2), float(EPISODE_STEPS), dtype=torch.float64))
    torch.testing.assert_close(result["return"], torch.full((3, 2), float(EPISODE_STEPS), dtype=torch.float64))
    assert len(steps) == 2 * EPISODE_STEPS  # stops as soon as every env has two episodes
    assert len(calls) == 2 and all(bool(mask.all()) for mask in calls)

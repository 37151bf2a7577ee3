"""roto's env contract (``roto.envs.contract.BatchedEnv``): the env and the learner's test env keep it."""

import roto
from roto.envs.config import EnvConfig
from roto.envs.contract import BatchedEnv
from tests.rl.toy_env import ToyEnv


def test_roto_env_and_the_toy_env_keep_the_contract():
    env = roto.make("bounce", num_envs=2)
    toy = ToyEnv(EnvConfig(task="bounce", num_envs=2))
    assert isinstance(env, BatchedEnv) and isinstance(toy, BatchedEnv)
    assert not isinstance(object(), BatchedEnv)  # a protocol check that can fail
    obs, _ = env.reset()
    assert set(obs) == set(env.frame_sizes) and env.aid_metrics() == {}
    env.close()

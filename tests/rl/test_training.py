import pytest
import torch

from roto.envs.config import EnvConfig
from roto.rl.config import load_agent_config
from roto.rl.runner import Trainer, TrainSettings
from tests.rl.toy_env import ToyEnv

TINY = [
    "network.encoder=[32, 32]",
    "network.policy_head=[16]",
    "network.value_head=[16]",
    "ppo.rollouts=4",
    "ppo.epochs=2",
    "ppo.minibatches=2",
    "run.num_eval_envs=2",
]


def tiny_trainer(tmp_path, name, updates, **kwargs):
    env = EnvConfig(task="bounce", robot="shadow", num_envs=4, seed=3)
    settings = TrainSettings(env=env, total_steps=16 * updates)
    agent = load_agent_config("bounce", overrides=TINY)
    return Trainer(settings, agent, tmp_path / name, tensorboard=False, **kwargs)


def params(trainer):
    return {k: v.clone() for k, v in trainer.model.state_dict().items()}


def test_same_seed_gives_identical_parameters(tmp_path):
    a = tiny_trainer(tmp_path, "a", 2)
    a.train(progress=False)
    b = tiny_trainer(tmp_path, "b", 2)
    b.train(progress=False)
    pa, pb = params(a), params(b)
    assert all(torch.equal(pa[k], pb[k]) for k in pa)
    # and training changed them
    fresh = params(tiny_trainer(tmp_path, "c", 2))
    assert not all(torch.equal(pa[k], fresh[k]) for k in pa)


def test_resume_continues_bit_identically(tmp_path):
    whole = tiny_trainer(tmp_path, "whole", 3)
    whole.train(progress=False)
    part = tiny_trainer(tmp_path, "part", 2)
    part.train(progress=False)
    resumed = Trainer.resume(tmp_path / "part", total_steps=16 * 3, tensorboard=False)
    assert resumed.update == 2
    resumed.train(progress=False)
    pw, pr = params(whole), params(resumed)
    assert all(torch.equal(pw[k], pr[k]) for k in pw)
    assert (
        resumed.alg.optimizer.state_dict()["state"][0]["step"] == whole.alg.optimizer.state_dict()["state"][0]["step"]
    )


def test_resume_without_a_checkpoint_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="roto run directory"):
        Trainer.resume(tmp_path)


def test_ppo_learns_the_toy_task(tmp_path):
    torch.set_num_threads(1)
    settings = TrainSettings(
        env=EnvConfig(task="bounce", obs_mode="proprio", num_envs=32, seed=0), total_steps=32 * 8 * 60
    )
    agent = load_agent_config(
        "bounce",
        overrides=[
            "network.encoder=[64, 64]",
            "network.policy_head=[32]",
            "network.value_head=[32]",
            "ppo.rollouts=8",
            "ppo.epochs=4",
            "ppo.minibatches=4",
            "ppo.lr=3e-3",
            "ppo.entropy_coef=0.0",
            "ppo.gamma=0.5",
            "run.num_eval_envs=16",
        ],
    )
    trainer = Trainer(settings, agent, tmp_path / "toy", tensorboard=False, env_factory=ToyEnv)
    last = trainer.train(progress=False)
    # random actions in [-1, 1] earn about 8 * (1 - 2/3) = 2.7 per 8-step episode; the optimum is 8
    assert last["eval/return_mean"] > 7.0, last

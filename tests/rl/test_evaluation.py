"""Training-time evaluation records the task's path metrics beside its metrics."""

from roto.envs.config import EnvConfig
from roto.rl.config import load_agent_config
from roto.rl.runner import Trainer, TrainSettings


def test_training_time_evaluations_of_baoding_record_the_pair_turns(tmp_path):
    env = EnvConfig(task="baoding", robot="shadow", num_envs=2, seed=3)
    agent = load_agent_config("baoding", overrides=["run.num_eval_envs=2", "ppo.rollouts=4", "ppo.minibatches=1"])
    trainer = Trainer(TrainSettings(env=env, total_steps=8), agent, tmp_path / "run", tensorboard=False)
    assert "privileged" in trainer.evaluator.env.config.extra_groups  # the blind policy still reads none of it
    record = trainer.evaluator.evaluate(trainer.model, update=0)
    assert len(record["per_episode"]["net_turns"]) == 2
    assert 0.0 <= record["net_turns_mean"] <= record["travelled_turns_mean"]

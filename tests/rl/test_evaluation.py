"""Training-time evaluation records the task's path metrics beside its metrics."""

from roto.envs.config import EnvConfig
from roto.rl.config_files import load_agent_config
from roto.rl.run_spec import RunSpec
from roto.rl.runner import Trainer


def test_training_time_evaluations_of_baoding_record_the_pair_turns(tmp_path):
    env = EnvConfig(task="baoding", robot="shadow", num_envs=2, seed=3)
    agent = load_agent_config("baoding", overrides=["run.num_eval_envs=2", "ppo.rollouts=4", "ppo.minibatches=1"])
    trainer = Trainer(RunSpec(env=env, agent=agent, steps=8), tmp_path / "run", tensorboard=False)
    assert "privileged" in trainer.evaluator.env.config.extra_groups  # the blind policy still reads none of it
    record = trainer.evaluator.evaluate(trainer.model, update=0)
    assert len(record["per_episode"]["net_turns"]) == 2
    assert 0.0 <= record["net_turns_mean"] <= record["travelled_turns_mean"]


def test_best_pt_goes_by_the_tasks_selection_metric_then_the_return():
    from roto.rl.evaluation import best_eval_key, load_best_eval

    swing = {"return_mean": 900.0, "round_rotations_mean": 0.25}
    round_ = {"return_mean": 500.0, "round_rotations_mean": 6.0}
    assert best_eval_key(round_, "round_rotations") > best_eval_key(swing, "round_rotations")
    assert best_eval_key(round_, None) < best_eval_key(swing, None)  # Bounce: the return alone
    older = {"return_mean": 950.0}  # an evaluation from before round rotations were measured
    assert best_eval_key(older, "round_rotations") < best_eval_key(swing, "round_rotations")
    assert load_best_eval({"best_eval_return": 7.0}, None) == (7.0, 7.0)
    assert load_best_eval({"best_eval_return": 7.0}, "round_rotations") == (float("-inf"), 7.0)
    assert load_best_eval({"best_eval": [6.0, 500.0], "best_eval_return": 500.0}, "round_rotations") == (6.0, 500.0)

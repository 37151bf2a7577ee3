import torch

from roto.envs.config import EnvConfig
from roto.envs.episodes import first_episodes
from roto.envs.observations import ball_positions, privileged_frame
from roto.envs.roto_env import RotoEnv
from roto.eval.ball_paths import with_ball_state
from roto.eval.evaluate import evaluate
from roto.rl.networks import ActorCritic
from roto.rl.runner import TrainSettings

BLIND_SHADOW_SIZES = {"tactile": 68, "proprio": 320}


def untrained_blind_policy() -> ActorCritic:
    torch.manual_seed(0)
    return ActorCritic(
        BLIND_SHADOW_SIZES, 20, actor_groups=("tactile", "proprio"), encoder=(32,), policy_head=(16,), value_head=(16,)
    )


def test_ball_positions_reads_the_newest_frame_of_a_stacked_privileged_group():
    frames = [torch.randn(3, 2, 3, dtype=torch.float64) for _ in range(4)]  # (B, n_ball, 3) per frame, oldest first
    stacked = torch.cat([privileged_frame(pos, torch.randn(3, 2, 3)) for pos in frames], dim=1)  # (B, 4 * 12)
    assert torch.equal(ball_positions(stacked, 2), frames[-1].to(torch.float32))


def test_the_ball_state_is_added_once_and_only_where_the_envs_lack_it():
    blind = EnvConfig(task="baoding", obs_mode="blind", extra_groups=("task",))
    assert with_ball_state(blind).extra_groups == ("task", "privileged")
    assert with_ball_state(with_ball_state(blind)) == with_ball_state(blind)
    state = EnvConfig(task="baoding", obs_mode="state")
    assert with_ball_state(state) is state


def test_a_baoding_evaluation_adds_the_pair_turns_and_leaves_the_episodes_as_they_were():
    settings = TrainSettings(env=EnvConfig(task="baoding", robot="shadow", num_envs=2))
    policy = untrained_blind_policy()
    summary = evaluate(policy, settings, episodes=2, seed=5)
    env = RotoEnv(settings.cpu_env_config(num_envs=2, seed=5))  # the same episodes without the ball state
    obs, _ = env.reset(seed=5)
    plain = first_episodes(env, policy.act_deterministic, obs)
    env.close()
    episodes = summary["per_episode"]
    assert episodes["return"] == plain["return"][:, 0].tolist() and episodes["swaps"] == plain["swaps"][:, 0].tolist()
    assert len(episodes["net_turns"]) == len(episodes["travelled_turns"]) == 2
    pairs = zip(episodes["net_turns"], episodes["travelled_turns"], strict=True)
    assert all(0.0 <= net <= travelled for net, travelled in pairs)
    assert sum(episodes["travelled_turns"]) > 0  # an untrained policy moves the balls some way


def test_a_bounce_evaluation_has_no_path_metrics():
    settings = TrainSettings(env=EnvConfig(task="bounce", robot="shadow", num_envs=1))
    summary = evaluate(untrained_blind_policy(), settings, episodes=1)
    assert set(summary["per_episode"]) == {"return", "length", "bounces"}


def test_training_time_evaluations_of_baoding_record_the_pair_turns(tmp_path):
    from roto.rl.config import load_agent_config
    from roto.rl.runner import Trainer

    env = EnvConfig(task="baoding", robot="shadow", num_envs=2, seed=3)
    agent = load_agent_config("baoding", overrides=["run.num_eval_envs=2", "ppo.rollouts=4", "ppo.minibatches=1"])
    trainer = Trainer(TrainSettings(env=env, total_steps=8), agent, tmp_path / "run", tensorboard=False)
    assert "privileged" in trainer.evaluator.env.config.extra_groups  # the blind policy still reads none of it
    record = trainer.evaluator.evaluate(trainer.model, update=0)
    assert len(record["per_episode"]["net_turns"]) == 2
    assert 0.0 <= record["net_turns_mean"] <= record["travelled_turns_mean"]

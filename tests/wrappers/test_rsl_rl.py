"""The RSL-RL adapter, proven by RSL-RL's own runner and PPO and against the batched env it wraps."""

import math

import pytest
import torch

import roto
from tests.conftest import require_extra

require_extra("rsl_rl", "rsl_rl")  # installed by `make test`
from rsl_rl.runners import OnPolicyRunner  # noqa: E402
from tensordict import TensorDict  # noqa: E402

from roto.envs.roto_env import RotoEnv  # noqa: E402
from roto.wrappers.rsl_rl import RslRlVecEnv  # noqa: E402

BLIND_ACTOR = {"actor": ["proprio", "tactile"], "critic": ["proprio", "tactile", "privileged"]}


def _train_cfg(num_steps_per_env: int) -> dict:
    """A small RSL-RL 5.5 runner config: PPO, a stochastic MLP actor and an MLP critic."""
    mlp = {"class_name": "MLPModel", "hidden_dims": [32, 32], "activation": "elu", "obs_normalization": True}
    return {
        "num_steps_per_env": num_steps_per_env,
        "save_interval": 100,
        "obs_groups": dict(BLIND_ACTOR),
        "algorithm": {"class_name": "PPO", "num_learning_epochs": 2, "num_mini_batches": 2},
        "actor": {**mlp, "distribution_cfg": {"class_name": "GaussianDistribution", "init_std": 1.0}},
        "critic": mlp,
    }


def _privileged_env(num_envs: int, **options) -> RotoEnv:
    """A blind bounce env that also returns the privileged group (for the critic)."""
    return roto.make("bounce", robot="shadow", num_envs=num_envs, seed=0, extra_groups=("privileged",), **options)


class _CountingVecEnv(RslRlVecEnv):
    """Counts the world-steps RSL-RL's runner takes."""

    world_steps = 0

    def step(self, actions):
        self.world_steps += self.num_envs
        return super().step(actions)


def test_steps_return_what_rsl_rl_expects_and_time_outs_end_episodes():
    env = _privileged_env(4, episode_steps=5)
    venv = RslRlVecEnv(env)
    reference = _privileged_env(4, episode_steps=5)
    expected_obs, _ = reference.reset()
    obs = venv.get_observations()
    assert isinstance(obs, TensorDict) and obs.batch_size == torch.Size([4])
    assert set(obs.keys()) == {"proprio", "tactile", "privileged"}
    for name, value in obs.items():
        assert value.shape == (4, 4 * env.frame_sizes[name]) and value.dtype == torch.float32
        assert value.device == env.device and torch.equal(value, expected_obs[name])
    assert venv.max_episode_length == 5 and venv.num_actions == env.num_actions
    hold = env.hold_action().repeat(4, 1)
    returns = torch.zeros(4)
    for step in range(1, 6):
        obs, rewards, dones, extras = venv.step(hold)
        expected_obs, expected_reward, terminated, _, _ = reference.step(hold)
        assert not terminated.any(), "holding still dropped the ball within 5 steps"
        assert rewards.shape == (4,) and rewards.dtype == torch.float32 and torch.equal(rewards, expected_reward)
        assert dones.shape == (4,) and dones.dtype == torch.int64 and dones.device == env.device
        assert extras["time_outs"].dtype == torch.bool
        assert all(torch.equal(obs[name], expected_obs[name]) for name in expected_obs)
        returns += rewards
        if step < 5:
            assert not dones.any() and not extras["time_outs"].any() and "log" not in extras
            assert torch.equal(venv.episode_length_buf, torch.full((4,), step))
    assert dones.tolist() == [1, 1, 1, 1] and extras["time_outs"].all()
    assert torch.equal(venv.episode_length_buf, torch.zeros(4, dtype=torch.int64))
    log = extras["log"]
    assert torch.equal(log["Episode/length"], torch.full((4,), 5.0))
    assert torch.equal(log["Episode/time_out"], torch.ones(4))
    assert torch.allclose(log["Episode/return"], returns) and "Episode/bounces" in log
    assert all(value.shape == (4,) and value.dtype == torch.float32 for value in log.values())


def test_rsl_rl_ppo_trains_on_the_batched_env(tmp_path, capsys):
    venv = _CountingVecEnv(_privileged_env(8, episode_steps=6))
    runner = OnPolicyRunner(venv, _train_cfg(num_steps_per_env=8), log_dir=str(tmp_path), device="cpu")
    # RSL-RL's log stores a git diff of the repo around rsl_rl's files: here this repo, which holds .venv
    runner.logger.git_status_repos.clear()
    losses = []
    update = runner.alg.update

    def recording_update() -> dict[str, float]:
        losses.append(update())
        return losses[-1]

    runner.alg.update = recording_update
    before = [p.detach().clone() for p in runner.alg.actor.parameters()]
    runner.learn(num_learning_iterations=3)
    assert venv.world_steps == 3 * 8 * 8
    assert len(losses) == 3 and all(math.isfinite(v) for loss in losses for v in loss.values())
    after = list(runner.alg.actor.parameters())
    assert all(torch.isfinite(p).all() for p in after)
    assert any(not torch.equal(a, b) for a, b in zip(after, before, strict=True)), "PPO changed nothing"
    printed = capsys.readouterr().out
    assert "Mean episode length:" in printed and "Episode/time_out:" in printed, "roto's episode log not logged"
    # RSL-RL stepped under torch.inference_mode; the env still steps outside it, with grad on (evaluation)
    policy = runner.get_inference_policy()
    obs, *_ = venv.step(policy(venv.get_observations()))
    assert torch.isfinite(obs["proprio"]).all() and not obs["proprio"].requires_grad


def test_blind_actor_reads_no_privileged_state_and_the_critic_does():
    venv = RslRlVecEnv(_privileged_env(2))
    runner = OnPolicyRunner(venv, _train_cfg(num_steps_per_env=4), log_dir=None, device="cpu")
    sizes = {name: value.shape[-1] for name, value in venv.get_observations().items()}
    actor, critic = runner.alg.actor, runner.alg.critic
    assert actor.obs_dim == sizes["proprio"] + sizes["tactile"]
    assert critic.obs_dim == sizes["proprio"] + sizes["tactile"] + sizes["privileged"]
    obs = venv.get_observations()
    moved = obs.clone()
    moved["privileged"] += 1.0
    with torch.no_grad():
        assert torch.equal(actor(obs), actor(moved))
        assert not torch.equal(critic(obs), critic(moved))


def test_staggered_episode_starts_are_a_clear_error():
    runner = OnPolicyRunner(RslRlVecEnv(_privileged_env(2)), _train_cfg(num_steps_per_env=2), device="cpu")
    with pytest.raises(AttributeError, match="init_at_random_ep_len=False"):
        runner.learn(num_learning_iterations=1, init_at_random_ep_len=True)


def test_a_gymnasium_env_is_refused_naming_the_adapter():
    import gymnasium

    with pytest.raises(TypeError, match=r"^RslRlVecEnv wraps a batched roto env"):
        RslRlVecEnv(gymnasium.make("roto/Bounce-Shadow-v0"))

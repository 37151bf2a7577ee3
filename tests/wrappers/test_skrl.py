"""The skrl adapter, proven by skrl's own PPO and SequentialTrainer and against the batched env it wraps."""

import math

import pytest
import torch
from torch import nn

import roto
from tests.conftest import require_extra

require_extra("skrl", "skrl")  # installed by `make test`
from skrl.agents.torch.ppo import PPO  # noqa: E402
from skrl.envs.wrappers.torch import Wrapper  # noqa: E402
from skrl.memories.torch import RandomMemory  # noqa: E402
from skrl.models.torch import DeterministicMixin, GaussianMixin, Model  # noqa: E402
from skrl.trainers.torch import SequentialTrainer  # noqa: E402

from roto.wrappers.skrl import SkrlWrapper, _summarise_episodes  # noqa: E402


class Policy(GaussianMixin, Model):
    """Gaussian policy: observations (B, n) -> mean actions (B, num_actions), state-independent log std."""

    def __init__(self, observation_space, action_space, device):
        Model.__init__(self, observation_space=observation_space, action_space=action_space, device=device)
        GaussianMixin.__init__(self, clip_actions=True)
        self.net = nn.Sequential(nn.Linear(self.num_observations, 32), nn.Tanh(), nn.Linear(32, self.num_actions))
        self.log_std = nn.Parameter(torch.full((self.num_actions,), -1.0))

    def compute(self, inputs, role=""):
        return self.net(inputs["observations"]), {"log_std": self.log_std}


class Critic(DeterministicMixin, Model):
    """Value of the states (B, s) -> (B, 1): the critic reads the privileged group the policy never sees."""

    def __init__(self, state_space, action_space, device):
        Model.__init__(self, state_space=state_space, action_space=action_space, device=device)
        DeterministicMixin.__init__(self)
        self.net = nn.Sequential(nn.Linear(self.num_states, 32), nn.Tanh(), nn.Linear(32, 1))

    def compute(self, inputs, role=""):
        return self.net(inputs["states"]), {}


class CountingWrapper(SkrlWrapper):
    """Counts the batched env's steps (each steps all B worlds once)."""

    steps = 0

    def step(self, actions):
        self.steps += 1
        return super().step(actions)


def _groups(obs, *names):
    return torch.cat([obs[name] for name in names], dim=-1)


def test_spaces_shapes_and_values_match_the_batched_env():
    options = dict(num_envs=4, seed=0, episode_steps=3, extra_groups=("privileged",))
    env = SkrlWrapper(roto.make("bounce", robot="shadow", **options))
    reference = roto.make("bounce", robot="shadow", **options)
    sizes = {name: space.shape[0] for name, space in reference.observation_space.items()}
    assert isinstance(env, Wrapper) and env.num_envs == 4 and env.num_agents == 1
    assert env.device == torch.device("cpu") and env.num_actions == reference.num_actions  # forwarded by skrl
    assert env.policy_groups == ("tactile", "proprio") and env.state_groups == ("tactile", "proprio", "privileged")
    assert env.observation_space.shape == (sizes["tactile"] + sizes["proprio"],)
    assert env.state_space.shape == (sum(sizes.values()),) and env.action_space.shape == (reference.num_actions,)

    obs, info = env.reset()
    expected, _ = reference.reset()
    assert obs.dtype == torch.float32 and obs.device == env.device and info == {}
    assert torch.equal(obs, _groups(expected, "tactile", "proprio"))
    assert torch.equal(env.state(), _groups(expected, "tactile", "proprio", "privileged"))
    action = reference.hold_action().repeat(4, 1)
    for step in range(1, 4):
        obs, reward, terminated, truncated, info = env.step(action)
        expected, expected_reward, _, expected_truncated, expected_info = reference.step(action)
        assert reward.shape == terminated.shape == truncated.shape == (4, 1)
        assert reward.dtype == torch.float32 and terminated.dtype == truncated.dtype == torch.bool
        assert torch.equal(obs, _groups(expected, "tactile", "proprio"))
        assert torch.equal(env.state(), _groups(expected, "tactile", "proprio", "privileged"))
        assert torch.equal(reward[:, 0], expected_reward) and torch.equal(truncated[:, 0], expected_truncated)
        assert not terminated.any() and truncated.all() == (step == 3) and ("episode" in info) == (step == 3)
    episode = info["episode"]
    assert episode["Episode / length"].item() == 3.0 and episode["Episode / time-out share"].item() == 1.0
    assert episode["Episode / return"].item() == pytest.approx(expected_info["episode"]["r"].mean().item())
    assert all(value.numel() == 1 for value in episode.values())  # what skrl's trainer logs
    assert torch.equal(env.reset()[0], obs), "a second reset() must not reset the worlds again"


def test_without_extra_groups_there_is_no_state():
    env = SkrlWrapper(roto.make("bounce", num_envs=2, obs_mode="proprio"))
    obs, _ = env.reset()
    assert env.policy_groups == ("proprio",) and env.state_space is None and env.state() is None
    assert obs.shape == (2, env.observation_space.shape[0]) == (2, 4 * env.unwrapped.frame_sizes["proprio"])
    privileged = SkrlWrapper(roto.make("bounce", num_envs=2, obs_mode="state"))
    assert privileged.policy_groups == ("tactile", "proprio", "privileged") and privileged.state_space is None


def test_episode_means_cover_only_the_worlds_that_ended():
    ended = torch.tensor([True, False, True])
    info = {
        "_episode": ended,
        "nonfinite": ended,
        "episode": {"r": torch.tensor([1.0, math.nan, 3.0]), "l": torch.tensor([4, 99, 6])},
    }
    summary = _summarise_episodes(info)
    assert {name: value.item() for name, value in summary["episode"].items()} == {
        "Episode / return": 2.0,
        "Episode / length": 5.0,
    }
    assert summary["nonfinite"] is ended and info["episode"]["l"].dtype == torch.int64  # the env's info untouched
    assert "episode" not in _summarise_episodes({**info, "_episode": torch.zeros(3, dtype=torch.bool)})


def test_sync_free_step_logs_episodes_only_when_they_end():
    roto_env = roto.make("bounce", num_envs=2, episode_steps=2)
    roto_env.sync_free_step = True  # as on a GPU: the env reports a masked episode dict every step
    env = SkrlWrapper(roto_env)
    env.reset()
    action = roto_env.hold_action().repeat(2, 1)
    assert "episode" not in env.step(action)[4]
    assert env.step(action)[4]["episode"]["Episode / length"].item() == 2.0


def test_skrl_ppo_trains_with_its_sequential_trainer(tmp_path):
    torch.manual_seed(0)
    # baoding: a dense reward, so the returns compared below are not all zero (bounce pays only per bounce)
    env = CountingWrapper(roto.make("baoding", num_envs=8, seed=0, episode_steps=10, extra_groups=("privileged",)))
    models = {
        "policy": Policy(env.observation_space, env.action_space, env.device),
        "value": Critic(env.state_space, env.action_space, env.device),
    }
    rollouts, updates = 8, 3
    cfg = {
        "rollouts": rollouts,
        "learning_epochs": 2,
        "mini_batches": 2,
        "time_limit_bootstrap": True,
        "experiment": {"directory": str(tmp_path), "write_interval": 1000, "checkpoint_interval": 0},
    }
    agent = PPO(
        models=models,
        memory=RandomMemory(memory_size=rollouts, num_envs=env.num_envs, device=env.device),
        observation_space=env.observation_space,
        state_space=env.state_space,
        action_space=env.action_space,
        device=env.device,
        cfg=cfg,
    )
    before = [p.detach().clone() for p in agent.policy.parameters()]
    trainer_cfg = {"timesteps": rollouts * updates, "headless": True, "disable_progressbar": True}
    SequentialTrainer(env=env, agents=agent, cfg={**trainer_cfg, "close_environment_at_exit": False}).train()

    assert env.steps == rollouts * updates
    data = agent.tracking_data
    assert len(data["Loss / Policy loss"]) == len(data["Loss / Value loss"]) == updates
    assert all(math.isfinite(x) for x in data["Loss / Policy loss"] + data["Loss / Value loss"])
    after = list(agent.policy.parameters())
    assert any(not torch.equal(a, b) for a, b in zip(after, before, strict=True)), "PPO changed nothing"
    # roto's episode statistics reached skrl's log and agree with what skrl summed from the rewards
    assert len(data["Episode / return"]) >= 2 and all(1 <= x <= 10 for x in data["Episode / length"])
    first_return = data["Episode / return"][0]
    assert first_return > 0.1 and first_return == pytest.approx(data["Reward / Total reward (mean)"][0], rel=1e-5)


def test_a_gymnasium_env_is_refused_naming_the_adapter():
    import gymnasium

    with pytest.raises(TypeError, match=r"^SkrlWrapper wraps a batched roto env"):
        SkrlWrapper(gymnasium.make("roto/Bounce-Shadow-v0"))

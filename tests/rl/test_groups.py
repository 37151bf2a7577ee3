"""Observation groups through the agent: what the actor and the critic read, for every hand and obs mode."""

import pytest
import torch

import roto
from roto.envs.observations import OBS_MODES
from roto.rl.build import build_model, extra_groups, resolve_groups, stacked_sizes
from roto.rl.config_files import load_agent_config

ROBOTS = ["shadow", "shadow_lite", "allegro", "orca"]
PRIVILEGED_CRITIC = ["network.critic=[tactile, proprio, privileged]", "network.encoder=[16]"]


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("obs_mode", list(OBS_MODES))
def test_the_actor_reads_exactly_the_obs_modes_groups_and_never_privileged_state(robot, obs_mode):
    agent = load_agent_config("baoding", overrides=PRIVILEGED_CRITIC)
    env = roto.make("baoding", robot=robot, num_envs=3, obs_mode=obs_mode, extra_groups=extra_groups(agent, obs_mode))
    obs, _ = env.reset(seed=0)
    sizes = stacked_sizes(env)
    model = build_model(sizes, env.num_actions, agent, obs_mode)
    assert model.actor_groups == OBS_MODES[obs_mode]
    assert model.actor_input.width == sum(sizes[g] for g in OBS_MODES[obs_mode])
    assert model.encoder[0].in_features == model.actor_input.width
    assert model.critic_groups == ("tactile", "proprio", "privileged")
    scrambled = {**obs, "privileged": obs["privileged"] + 100.0}
    assert not torch.equal(model.value(obs), model.value(scrambled))
    if obs_mode == "state":  # the state-based policy reads the ball state; one encoder serves both
        assert model.critic_input is None
        assert not torch.equal(model.act_deterministic(obs), model.act_deterministic(scrambled))
    else:  # a blind or proprio-only policy never does; the critic has its own encoder
        assert model.critic_input.width == sum(sizes.values())
        assert torch.equal(model.act_deterministic(obs), model.act_deterministic(scrambled))
    env.close()


def test_blind_env_returns_the_privileged_group_only_when_a_critic_asks_for_it():
    plain = load_agent_config("bounce")
    asking = load_agent_config("bounce", overrides=PRIVILEGED_CRITIC)
    assert extra_groups(plain, "blind") == ()
    assert extra_groups(asking, "blind") == ("privileged",)
    assert extra_groups(asking, "state") == ()
    env = roto.make("bounce", num_envs=2, extra_groups=("privileged",))
    obs, _ = env.reset(seed=0)
    assert list(obs) == ["tactile", "proprio", "privileged"]
    assert env.frame_sizes["privileged"] == 6
    env.close()


def test_reconstruction_targets_are_provided_by_the_env():
    agent = load_agent_config("bounce", overrides=["ssl.full_reconstruction={}"])
    assert resolve_groups(agent, "proprio").needed == ("tactile", "proprio")
    assert extra_groups(agent, "proprio") == ("tactile",)


def test_an_actor_group_outside_the_obs_mode_is_rejected_naming_the_valid_ones():
    agent = load_agent_config("bounce", overrides=["network.actor=[proprio, privileged]"])
    with pytest.raises(ValueError, match=r"network.actor reads \['privileged'\].*\['tactile', 'proprio'\]"):
        resolve_groups(agent, "blind")
    assert resolve_groups(agent, "state").actor == ("proprio", "privileged")


def test_unknown_or_repeated_groups_are_config_errors():
    with pytest.raises(ValueError, match=r"unknown observation group 'vision'.*'privileged'"):
        load_agent_config("bounce", overrides=["network.critic=[proprio, vision]"])
    with pytest.raises(ValueError, match="names a group twice"):
        load_agent_config("bounce", overrides=["network.actor=[proprio, proprio]"])
    with pytest.raises(ValueError, match=r"unknown extra observation group 'xray'"):
        roto.make("bounce", extra_groups=("xray",))

"""The ``task`` observation group: the task's own state and the time left, for critics only."""

import pytest
import torch

import roto
from roto.envs.observations import OBS_MODES
from roto.envs.single_world import supports_single_world_step
from roto.rl.build import build_model, extra_groups, resolve_groups, stacked_sizes
from roto.rl.config_files import load_agent_config

TASK_CRITIC = ["network.critic=[tactile, proprio, privileged, task]", "network.encoder=[16]"]


def newest(obs: dict[str, torch.Tensor], env, group: str = "task") -> torch.Tensor:
    return obs[group][:, -env.frame_sizes[group] :]


def test_baoding_task_frame_holds_current_targets_latches_and_time_left():
    env = roto.make("baoding", robot="shadow", num_envs=3, extra_groups=("task",), seed=0)
    assert env.frame_sizes["task"] == 9 and "task" not in OBS_MODES["blind"]
    obs, _ = env.reset()
    targets = env.task_state.targets.to(torch.float32)
    fresh = torch.cat([targets.flatten(), torch.zeros(2), torch.ones(1)])
    assert torch.equal(obs["task"], fresh.repeat(3, 4))  # four copies of the first frame
    hold = env.hold_action().expand(3, -1)
    for step in range(1, 6):
        obs, *_ = env.step(hold)
        frame = newest(obs, env)
        assert torch.allclose(frame[:, -1], torch.full((3,), 1.0 - step / 600))
    # the frame follows the assignment and the latches
    env.task_state.swapped[1] = True
    env.task_state.latched[1, 0] = True
    frame = env.task_state_frame()
    assert torch.equal(frame[1, :6], targets.flip(0).flatten()) and frame[1, 6:8].tolist() == [1.0, 0.0]
    assert torch.equal(frame[0, :6], targets.flatten()) and frame[0, 6:8].tolist() == [0.0, 0.0]
    env.close()


def test_bounce_task_frame_is_its_counter_state_in_unit_range():
    env = roto.make("bounce", robot="shadow", num_envs=2, extra_groups=("task",), seed=0)
    assert env.frame_sizes["task"] == 4
    env.reset()
    state = env.task_state
    state.prev_contact[:] = torch.tensor([True, False])
    state.waiting[:] = torch.tensor([False, True])
    state.steps_without_contact[:] = torch.tensor([2, 40])
    frame = env.task_state_frame()
    torch.testing.assert_close(frame[:, :3], torch.tensor([[1.0, 0.0, 0.4], [0.0, 1.0, 1.0]]))
    env.close()


@pytest.mark.parametrize("obs_mode", ["blind", "proprio"])
def test_a_task_critic_reads_the_task_state_and_the_policy_never_does(obs_mode):
    agent = load_agent_config("baoding", overrides=TASK_CRITIC)
    assert "task" in extra_groups(agent, obs_mode)
    env = roto.make("baoding", num_envs=2, obs_mode=obs_mode, extra_groups=extra_groups(agent, obs_mode))
    obs, _ = env.reset(seed=0)
    model = build_model(stacked_sizes(env), env.num_actions, agent, obs_mode)
    assert "task" in model.critic_groups and "task" not in model.actor_groups
    scrambled = {**obs, "task": obs["task"] + 1.0}
    assert torch.equal(model.act_deterministic(obs), model.act_deterministic(scrambled))
    assert not torch.equal(model.value(obs), model.value(scrambled))
    env.close()


def test_an_actor_that_asks_for_the_task_group_is_refused():
    agent = load_agent_config("baoding", overrides=["network.actor=[proprio, task]"])
    with pytest.raises(ValueError, match=r"network.actor reads \['task'\]"):
        resolve_groups(agent, "state")


def test_the_one_world_fast_step_steps_aside_for_the_task_group():
    plain = roto.make("baoding", num_envs=1)
    with_task = roto.make("baoding", num_envs=1, extra_groups=("task",))
    assert supports_single_world_step(plain) and not supports_single_world_step(with_task)
    plain.close()
    with_task.close()

import numpy as np
import torch

from tests.conftest import make_env


def test_time_out_truncates_at_episode_steps_and_resets_in_the_same_step():
    env = make_env("baoding", num_envs=2, episode_steps=30)
    env.reset()
    hold = env.hold_action()[0]
    for step in range(1, 31):
        _, _, terminated, truncated, info = env.step(hold.expand(2, -1))
        assert not terminated.any()
        assert truncated.all() == (step == 30) and truncated.any() == (step == 30)
    assert info["episode"]["time_out"].all() and info["episode"]["l"].tolist() == [30, 30]
    assert env.episodes.length.tolist() == [0, 0]  # already reset within the step
    env.close()


def test_episode_info_and_final_obs_on_termination():
    env = make_env("bounce", num_envs=3, obs_mode="state")
    env.reset()
    # move every ball far below the palm: all three terminate on the next step
    state = env.backend.state
    qpos = torch.from_numpy(env.backend.qpos.copy())
    qpos[:, env.indices.ball_pos.index[0, 2]] = -0.5
    env.backend.set_state(torch.arange(3), qpos, torch.zeros(3, env.model.nv))
    obs, _, terminated, truncated, info = env.step(torch.zeros(3, 20))
    assert terminated.all() and not truncated.any()
    assert info["_episode"].all() and torch.equal(info["episode"]["l"], torch.ones(3, dtype=torch.int64))
    assert info["final_obs"]["privileged"][:, -4].max() < -0.4  # terminal ball height
    assert obs["privileged"][:, -4].min() > 0.05  # reset: ball back above the palm
    assert "bounces" in info["episode"] and not info["episode"]["time_out"].any()
    assert np.isfinite(state).all()
    env.close()


def test_non_finite_world_is_reset_and_counted_others_untouched():
    env = make_env("bounce", num_envs=3)
    env.reset()
    for _ in range(3):
        env.step(torch.zeros(3, 20))
    qvel = torch.from_numpy(env.backend.qvel.copy())
    qvel[1, 0] = float("nan")
    qpos = torch.from_numpy(env.backend.qpos.copy())
    env.backend.set_state(torch.tensor([1]), qpos[1:2], qvel[1:2])
    reference = make_env("bounce", num_envs=3)
    reference.reset()
    for _ in range(3):
        reference.step(torch.zeros(3, 20))
    obs, reward, terminated, _, info = env.step(torch.zeros(3, 20))
    ref_obs, *_ = reference.step(torch.zeros(3, 20))
    assert info["nonfinite"].tolist() == [False, True, False]
    assert env.nonfinite_resets == 1 and terminated[1] and reward[1] == 0
    for name in obs:
        assert torch.isfinite(obs[name]).all()
        assert torch.equal(obs[name][[0, 2]], ref_obs[name][[0, 2]])
    env.close()
    reference.close()

"""Replayed starts: a share of training episodes starts from recorded pre-swap states, exactly as
recorded, resumably; share 0 changes nothing and evaluation never replays."""

import numpy as np
import pytest
import torch

import roto
from roto.envs.aids.replayed_starts import ReplayedStarts
from roto.envs.config import EnvConfig
from roto.rl.run_spec import RunSpec
from tests.conftest import SHADOW_BANK

BANK = SHADOW_BANK  # the Shadow reference controller's pre-swap states


def replay_env(share: float, num_envs: int = 4, seed: int = 0, **kwargs):
    return roto.make("baoding", robot="shadow", num_envs=num_envs, seed=seed, aids=replayed(BANK, share), **kwargs)


def replayed(bank: str, share: float) -> dict:
    """The aids section of an env that replays ``share`` of its starts from ``bank``."""
    return {"replayed_starts": {"bank": bank, "share": share}}


def run(env, steps: int = 40) -> list[dict[str, torch.Tensor]]:
    gen = torch.Generator().manual_seed(0)
    obs, _ = env.reset()
    out = [obs]
    for _ in range(steps):
        obs, *_ = env.step(torch.rand(env.num_envs, env.num_actions, generator=gen) * 2 - 1)
        out.append(obs)
    return out


def test_share_zero_changes_nothing():
    plain = roto.make("baoding", robot="shadow", num_envs=4, seed=0)
    zero = replay_env(0.0)
    for a, b in zip(run(plain), run(zero), strict=True):
        assert all(torch.equal(a[k], b[k]) for k in a)


def test_every_replayed_start_is_the_recorded_state_with_its_latches():
    saved = np.load(BANK)
    env = replay_env(1.0, extra_groups=("task",))
    starts = env.starts.draw(32)
    assert starts["replayed"].all()
    bank = env.aid(ReplayedStarts).bank
    for q, v, t, swapped, latched in zip(
        starts["qpos"], starts["qvel"], starts["target"], starts["task/swapped"], starts["task/latched"], strict=True
    ):
        k = int(torch.nonzero((bank.qpos == q).all(dim=1))[0])  # which recorded state it is
        assert torch.equal(v, bank.qvel[k]) and torch.equal(t, bank.target[k])
        assert bool(swapped) == bool(saved["swapped"][k]) and latched.tolist() == saved["latched"][k].tolist()
    obs, _ = env.reset()
    physics = torch.from_numpy(env.backend.physics_state())
    for world in range(env.num_envs):  # each world starts in a recorded state and its task state
        k = int(torch.nonzero((bank.qpos == physics[world, 1 : 1 + env.model.nq]).all(dim=1))[0])
        assert bool(env.task_state.swapped[world]) == bool(saved["swapped"][k])
        assert env.task_state.latched[world].tolist() == saved["latched"][k].tolist()
    assert env.task_state.latched.any()  # ball a had latched before most recorded swaps
    newest = obs["task"][:, -9:]  # the first frame's task group shows the recorded latches
    assert torch.equal(newest[:, 6:8], env.task_state.latched.to(torch.float32))
    env.close()


def test_a_share_of_starts_is_replayed_the_rest_are_the_task_s_own():
    env = replay_env(0.25)
    starts = env.starts.draw(400)
    share = float(starts["replayed"].to(torch.float64).mean())
    assert 0.18 < share < 0.32
    fresh = ~starts["replayed"]
    assert torch.all(starts["qvel"][fresh] == 0) and not starts["task/latched"][fresh].any()
    assert torch.all(starts["qpos"][fresh][:, env.layout.ball_qpos[0] + 2] > 0.08)  # dropped from above
    env.close()


def test_resume_continues_bit_identically_with_replayed_starts():
    gen = torch.Generator().manual_seed(1)
    actions = torch.rand(120, 4, 20, generator=gen) * 2 - 1
    first = replay_env(0.5, seed=3)
    first.reset()
    for a in actions[:60]:
        first.step(a)
    saved = first.state_dict()
    second = replay_env(0.5, seed=99)
    second.load_state_dict(saved)
    for a in actions[60:]:
        obs_a, rew_a, *_ = first.step(a)
        obs_b, rew_b, *_ = second.step(a)
        assert torch.equal(rew_a, rew_b) and all(torch.equal(obs_a[k], obs_b[k]) for k in obs_a)


def test_evaluation_envs_never_replay():
    env = EnvConfig(task="baoding", aids=replayed(BANK, 0.5))
    settings = RunSpec(env=env)
    assert (
        settings.eval_env_config(8, 1).aids.replayed_starts is None and settings.eval_env_config().aids.active() == {}
    )
    assert settings.cpu_env_config(1).aids.replayed_starts is None
    assert settings.env_config().aids.replayed_starts.share == 0.5  # the training envs keep their aid


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        (replayed(BANK, 1.5), r"aids.replayed_starts.share must be a share in \[0, 1\], got 1.5"),
        ({"replayed_starts": {"share": 0.5}}, r"aids.replayed_starts needs \['bank'\], got \{'share': 0.5\}"),
        (
            {"replayed_starts": {"bank": BANK, "shares": 0.5}},
            r"unknown setting\(s\) \['shares'\] of aids.replayed_starts",
        ),
        ({"replay": {"bank": BANK}}, r"unknown training aid aids.replay; valid aids: \['replayed_starts'"),
    ],
)
def test_bad_replay_settings_are_refused(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        EnvConfig(task="baoding", aids=kwargs)


def test_a_missing_states_file_is_refused_by_the_env_and_a_run_s_config_still_loads():
    with pytest.raises(ValueError, match=r"aids.replayed_starts.bank '/nowhere/states.npz' is not a file"):
        roto.make("baoding", aids=replayed("/nowhere/states.npz", 0.5))
    # a run trained with the aid is still evaluated where the file is gone (eval drops the aid)
    settings = RunSpec.from_dict(
        {"env": {"task": "baoding", "aids": replayed("/nowhere/states.npz", 0.5)}, "agent": {}, "steps": 10}
    )
    env = roto.make(**vars(settings.eval_env_config(num_envs=1)))
    assert env.aid(ReplayedStarts) is None
    env.close()


def test_states_of_another_hand_are_refused():
    with pytest.raises(ValueError, match=r"states recorded on robot 'shadow', not this env's 'allegro'"):
        roto.make("baoding", robot="allegro", aids=replayed(BANK, 0.5))


def test_both_backends_draw_the_same_replayed_starts():
    from tests.conftest import require_warp

    require_warp()
    cpu, warp = replay_env(0.5, seed=4), replay_env(0.5, seed=4, backend="warp")
    a, b = cpu.starts.draw(16), warp.starts.draw(16)
    assert torch.equal(a["replayed"], b["replayed"]) and a["replayed"].any() and not a["replayed"].all()
    assert torch.equal(a["qpos"], b["qpos"]) and torch.equal(a["qvel"], b["qvel"])
    assert torch.equal(a["frame/tactile"], b["frame/tactile"])
    cpu.close()
    warp.close()


@pytest.mark.parametrize("robot", ["shadow_lite", "allegro", "orca"])
def test_every_hands_bank_replays_in_its_own_scene_with_the_task_state_it_was_recorded_in(robot):
    bank_file = BANK.replace("shadow_preswap", f"{robot}_preswap")
    env = roto.make("baoding", robot=robot, num_envs=8, seed=0, aids=replayed(bank_file, 1.0))
    obs, _ = env.reset()
    saved, bank = np.load(bank_file), env.aid(ReplayedStarts).bank
    physics = torch.from_numpy(env.backend.physics_state())
    for world in range(env.num_envs):  # each world is one recorded state, with its own latches
        k = int(torch.nonzero((bank.qpos == physics[world, 1 : 1 + env.model.nq]).all(dim=1))[0])
        assert bool(env.task_state.swapped[world]) == bool(saved["swapped"][k])
        assert env.task_state.latched[world].tolist() == saved["latched"][k].tolist()
    assert all(torch.isfinite(value).all() for value in obs.values())
    env.close()

import pytest
import torch

import roto
from roto.robots.spec import with_baoding_geometry
from tests.conftest import make_env


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"task": "juggle"}, r"unknown task 'juggle'.*baoding.*bounce"),
        ({"task": "bounce", "robot": "leap"}, r"unknown robot 'leap'.*shadow"),
        ({"task": "bounce", "obs_mode": "vision"}, r"unknown obs_mode 'vision'.*blind.*state.*proprio"),
        ({"task": "bounce", "num_envs": 0}, r"num_envs must be an integer >= 1, got 0"),
        ({"task": "bounce", "backend": "jax"}, r"unknown backend 'jax'.*cpu"),
        ({"task": "bounce", "device": "cuda"}, r"device 'cuda' is not available"),
        ({"task": "bounce", "frame_stack": "4"}, r"frame_stack must be an integer >= 1, got '4'"),
        ({"task": "bounce", "episode_steps": 10.5}, r"episode_steps must be an integer >= 1, got 10.5"),
        ({"task": "bounce", "seed": -1}, r"seed must be an integer in \[0, 9223372036854775807\], got -1"),
        ({"task": "bounce", "seed": 0.5}, r"seed must be an integer in \[0, 9223372036854775807\], got 0.5"),
        ({"task": "bounce", "action_smoothing": "1"}, r"action_smoothing must be a number in \(0, 1\], got '1'"),
        (
            {"task": "bounce", "tactile_threshold": -1.0},
            r"tactile_threshold must be a force \(N\) in \[0, inf\), got -1.0",
        ),
        (
            {"task": "bounce", "tactile_threshold": float("nan")},
            r"tactile_threshold must be a force \(N\) in \[0, inf\), got nan",
        ),
        (
            {"task": "bounce", "reset_joint_noise": -0.1},
            r"reset_joint_noise must be a half-width \(rad\) in \[0, inf\), got -0.1",
        ),
    ],
)
def test_bad_construction_arguments(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        roto.make(**kwargs)


def test_names_are_case_insensitive():
    env = roto.make("BOUNCE", robot="Shadow")
    assert env.task.name == "bounce"
    env.close()


@pytest.fixture
def env():
    env = make_env("bounce", num_envs=2)
    env.reset()
    yield env
    env.close()


def test_wrong_action_shape(env):
    with pytest.raises(ValueError, match=r"action shape \(2, 19\) is wrong; expected .* \(2, 20\)"):
        env.step(torch.zeros(2, 19))


def test_wrong_action_dtype(env):
    with pytest.raises(TypeError, match=r"action dtype torch.int64 is not floating point"):
        env.step(torch.zeros(2, 20, dtype=torch.int64))


def test_action_not_a_tensor(env):
    with pytest.raises(TypeError, match=r"action must be a torch.Tensor"):
        env.step([[0.0] * 20] * 2)


def test_wrong_action_device(env):
    with pytest.raises(ValueError, match=r"action is on device meta; this env runs on cpu"):
        env.step(torch.zeros(2, 20, device="meta"))


def test_non_finite_action_names_the_env_and_loses_nothing(env):
    before = env.backend.state.copy()
    action = torch.zeros(2, 20)
    action[1, 3] = float("nan")
    with pytest.raises(ValueError, match=r"non-finite values .* in envs \[1\]"):
        env.step(action)
    assert (env.backend.state == before).all()
    env.step(torch.zeros(2, 20))  # still usable


def test_step_before_reset():
    env = make_env("bounce")
    with pytest.raises(RuntimeError, match="reset"):
        env.step(torch.zeros(2, 20))


def test_step_never_modifies_the_callers_action(env):
    action = torch.full((2, 20), 0.5)
    for _ in range(40):  # long enough for terminations and resets
        env.step(action)
    assert torch.all(action == 0.5)


def test_a_baoding_drop_inside_the_hand_is_refused_when_the_env_is_made(monkeypatch):
    """Balls 'dropped' from the palm surface start half inside it: the env refuses, naming the hand and depth."""

    import roto.robots as robots

    sunk = with_baoding_geometry(robots.ROBOTS["shadow"], drop_centre=(0.0, 0.0, 0.0))
    monkeypatch.setitem(robots.ROBOTS, "shadow", sunk)
    with pytest.raises(ValueError, match=r"robot 'shadow', task 'baoding': the balls start [0-9.]+-[0-9.]+ mm deep"):
        roto.make("baoding", robot="shadow")

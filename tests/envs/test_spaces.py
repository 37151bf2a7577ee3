import gymnasium
import numpy as np
import pytest
import torch

from roto.envs.spaces import BoundedBox
from roto.registry import list_envs
from tests.conftest import make_env

# docs/spec.md §3 per robot: tactile links, proprio = 2 * observed joints + 2 * actions, actions
TABLE = {"shadow": (17, 80, 20), "shadow_lite": (14, 58, 13), "allegro": (20, 64, 16), "orca": (17, 68, 17)}


@pytest.mark.parametrize(("task", "robot"), list_envs())
@pytest.mark.parametrize("obs_mode", ["blind", "state", "proprio"])
def test_observation_sizes_dtypes_and_spaces(task, robot, obs_mode):
    env = make_env(task, robot=robot, obs_mode=obs_mode, num_envs=3)
    tactile, proprio, actions = TABLE[robot]
    expected = {"tactile": tactile, "proprio": proprio} if obs_mode != "proprio" else {"proprio": proprio}
    if obs_mode == "state":
        expected["privileged"] = 6 if task == "bounce" else 12
    assert env.frame_sizes == expected
    obs, _ = env.reset()
    obs2, reward, terminated, truncated, _ = env.step(torch.zeros(3, actions))
    for o in (obs, obs2):
        assert list(o) == list(expected)
        for name, value in o.items():
            assert value.dtype == torch.float32 and value.shape == (3, 4 * expected[name])
            assert env.observation_space[name].contains(value[0].numpy())
    assert reward.shape == (3,) and terminated.dtype == torch.bool and truncated.dtype == torch.bool
    assert env.action_space.shape == (actions,)
    env.close()


def test_shadow_blind_frame_is_97_and_stack_388():
    env = make_env("bounce", obs_mode="blind")
    assert sum(env.frame_sizes.values()) == 97
    obs, _ = env.reset()
    assert sum(v.shape[1] for v in obs.values()) == 388


def test_stack_is_filled_with_copies_of_the_first_frame_at_reset():
    env = make_env("bounce", num_envs=2)
    obs, _ = env.reset()
    frames = obs["proprio"].reshape(2, 4, -1)
    for k in range(1, 4):
        torch.testing.assert_close(frames[:, k], frames[:, 0])
    obs, *_ = env.step(torch.zeros(2, 20))
    frames2 = obs["proprio"].reshape(2, 4, -1)
    torch.testing.assert_close(frames2[:, :3], frames[:, 1:])  # oldest dropped, newest appended
    assert not torch.equal(frames2[:, 3], frames[:, 3])


def test_proprio_normalised_positions_are_within_bounds():
    env = make_env("baoding", num_envs=4)
    obs, _ = env.reset()
    pos = obs["proprio"].reshape(4, 4, -1)[:, -1, :20]
    assert torch.all(pos >= -1.0001) and torch.all(pos <= 1.0001)
    assert np.isfinite(obs["proprio"].numpy()).all()


@pytest.mark.parametrize(
    ("low", "high", "shape"),
    [
        (-1.0, 1.0, (20,)),  # roto's action space
        (-0.3, 2.7, (5,)),
        # per-coordinate bounds
        (np.array([[-1.0, 0.0], [-3.0, 2.0]], np.float32), np.array([[1.0, 5.0], [0.0, 2.5]], np.float32), None),
    ],
)
def test_bounded_box_samples_what_gymnasium_box_samples(low, high, shape):
    reference = gymnasium.spaces.Box(low, high, shape, np.float32)
    box = BoundedBox(low, high, shape, np.float32)
    assert box == reference
    reference.seed(7)
    box.seed(7)
    for _ in range(200):
        sample = box.sample()
        assert sample.dtype == np.float32 and box.contains(sample)
        np.testing.assert_array_equal(sample, reference.sample())


def test_bounded_box_refuses_unbounded_or_integer_boxes_and_masks():
    with pytest.raises(ValueError, match="finite bounds"):
        BoundedBox(-np.inf, 1.0, (3,), np.float32)
    with pytest.raises(ValueError, match="float dtype"):
        BoundedBox(0, 5, (3,), np.int64)
    with pytest.raises(gymnasium.error.Error, match="mask"):
        BoundedBox(-1.0, 1.0, (3,), np.float32).sample(mask=np.ones(3))


def test_env_action_space_is_a_bounded_box():
    env = make_env("bounce", robot="shadow", num_envs=1)
    assert isinstance(env.action_space, BoundedBox) and isinstance(env.action_space, gymnasium.spaces.Box)
    assert env.action_space == gymnasium.spaces.Box(-1.0, 1.0, (env.num_actions,), np.float32)
    env.close()

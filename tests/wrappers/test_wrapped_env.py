import gymnasium
import pytest

import roto
from roto.wrappers.wrapped_env import require_roto_env


def test_a_roto_env_passes_and_anything_else_is_a_type_error_naming_the_adapter():
    env = roto.make("bounce", num_envs=2)
    assert require_roto_env(env, "Sb3VecEnv") is env
    one_world = gymnasium.make("roto/Bounce-Shadow-v0")
    with pytest.raises(TypeError, match=r"^Sb3VecEnv wraps a batched roto env, roto.make\(.*got OrderEnforcing"):
        require_roto_env(one_world, "Sb3VecEnv")
    with pytest.raises(TypeError, match=r"a Gymnasium env from gymnasium.make or make_vec is not one"):
        require_roto_env("bounce", "SkrlWrapper")
    env.close()
    one_world.close()

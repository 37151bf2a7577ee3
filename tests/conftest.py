import importlib.util
import os

import pytest
import torch

import roto


@pytest.fixture(autouse=True)
def _one_torch_thread():
    torch.set_num_threads(1)


def make_env(task: str = "bounce", **kwargs):
    kwargs.setdefault("num_envs", 2)
    return roto.make(task, **kwargs)


def require_warp() -> None:
    """Skip without MuJoCo Warp, unless ROTO_REQUIRE_WARP is set (``make test``), then fail."""
    if importlib.util.find_spec("mujoco_warp") is None:
        if os.environ.get("ROTO_REQUIRE_WARP"):
            pytest.fail("MuJoCo Warp is not installed but ROTO_REQUIRE_WARP is set: pip install -e '.[gpu]'")
        pytest.skip("MuJoCo Warp is not installed (pip install -e '.[gpu]')")

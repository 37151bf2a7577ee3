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


def require_extra(module: str, extra: str) -> None:
    """Skip without an optional extra's package, unless ROTO_REQUIRE_EXTRAS is set (``make test``),
    then fail."""
    if importlib.util.find_spec(module) is None:
        if os.environ.get("ROTO_REQUIRE_EXTRAS"):
            pytest.fail(f"{module} is not installed but ROTO_REQUIRE_EXTRAS is set: pip install -e '.[{extra}]'")
        pytest.skip(f"{module} is not installed (pip install -e '.[{extra}]')", allow_module_level=True)


def require_warp() -> None:
    """Skip without MuJoCo Warp, unless ROTO_REQUIRE_WARP is set (``make test``), then fail."""
    if importlib.util.find_spec("mujoco_warp") is None:
        if os.environ.get("ROTO_REQUIRE_WARP"):
            pytest.fail("MuJoCo Warp is not installed but ROTO_REQUIRE_WARP is set: pip install -e '.[gpu]'")
        pytest.skip("MuJoCo Warp is not installed (pip install -e '.[gpu]')")

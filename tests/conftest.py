import contextlib
import importlib.util
import os
import pathlib

import pytest
import torch
from torch.utils._python_dispatch import TorchDispatchMode

import roto

SHADOW_BANK = str(pathlib.Path(__file__).resolve().parents[1] / "roto/banks/shadow_preswap.npz")
"""The Shadow reference controller's pre-swap states (a packaged bank, ``shadow_preswap``)."""

BAODING_AIDS = {
    "aids": {
        "replayed_starts": {"bank": SHADOW_BANK, "share": 0.5, "record_lead": 10},
        "tolerance": {"start": 0.025, "target": 2.0},
        "round_swaps": {"min_turn": 0.25},
        "turn_shaping": {"per_turn": 20.0},
    }
}
"""Every training aid of the Baoding recipes at once (baoding_cpu, and the round swaps of
experiments/baoding_configs/baoding_cpu_orca_round.yaml)."""

HOST_READS = ("aten._local_scalar_dense", "aten.nonzero", "aten.masked_select", "aten.unique", "aten._unique2")
"""Ops that read a tensor's values back to the host (``.item()``, ``bool()``, indexing by a 0-d tensor,
boolean masks, data-dependent shapes): on a GPU each waits for the device."""


class HostReads(TorchDispatchMode):
    """Records every ``HOST_READS`` op run while it is active and not paused."""

    def __init__(self) -> None:
        super().__init__()
        self.seen: list[str] = []
        self.paused = False

    def __torch_dispatch__(self, func, types, args=(), kwargs=None):
        if not self.paused and str(func).startswith(HOST_READS):
            self.seen.append(str(func))
        return func(*args, **(kwargs or {}))


@pytest.fixture
def host_reads(monkeypatch) -> HostReads:
    """A ``HostReads`` mode (enter it around the code under test) that pauses inside roto's deliberate
    host reads, with the CPU-only shortcut ``zero_on_host`` answering as for a GPU tensor: on Warp's
    CPU device it then sees what a GPU run would wait for."""
    import roto.envs.roto_env
    import roto.rl.runner
    import roto.sim.mujoco_warp
    import roto.tasks.baoding

    reads = HostReads()

    @contextlib.contextmanager
    def deliberate(device):
        reads.paused = True
        try:
            yield
        finally:
            reads.paused = False

    for module in (roto.envs.roto_env, roto.sim.mujoco_warp, roto.rl.runner):
        monkeypatch.setattr(module, "deliberate_host_sync", deliberate)
    monkeypatch.setattr(roto.tasks.baoding, "zero_on_host", lambda x: False)
    return reads


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

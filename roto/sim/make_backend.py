"""The physics backend by name: the one place that imports a backend's module (and so Warp)."""

from __future__ import annotations

import mujoco

from roto.sim.backend import BACKENDS, Backend


def make_backend(
    name: str,
    model: mujoco.MjModel,
    num_worlds: int,
    *,
    substeps: int,
    threads: int = 1,
    device: str = "cpu",
    nconmax: int | None = None,
    njmax: int | None = None,
) -> Backend:
    """The backend ``name`` for B = ``num_worlds`` worlds of ``model`` (Warp is imported only here).

    ``threads`` applies to ``cpu``; ``device``, ``nconmax`` and ``njmax`` (per-world capacities)
    to ``warp``.
    """
    if name == "cpu":
        from roto.sim.mujoco_cpu import MujocoCpuBackend

        return MujocoCpuBackend(model, num_worlds, substeps=substeps, threads=threads)
    if name == "warp":
        from roto.sim.mujoco_warp import MujocoWarpBackend

        if nconmax is None or njmax is None:
            raise ValueError("backend 'warp' needs the per-world capacities nconmax and njmax")
        return MujocoWarpBackend(model, num_worlds, substeps=substeps, device=device, nconmax=nconmax, njmax=njmax)
    raise ValueError(f"unknown backend {name!r}; valid backends: {list(BACKENDS)}")

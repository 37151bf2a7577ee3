"""Whether a batch of worlds fits in this machine's memory, asked before anything is allocated."""

from __future__ import annotations

import pathlib

import mujoco

GIB = 1024**3


def available_memory() -> int | None:
    """Bytes of memory available to new allocations (Linux ``MemAvailable``), or None where unknown."""
    meminfo = pathlib.Path("/proc/meminfo")
    if not meminfo.is_file():
        return None
    for line in meminfo.read_text().splitlines():
        if line.startswith("MemAvailable:"):
            return int(line.split()[1]) * 1024
    return None


def cpu_batch_bytes(model: mujoco.MjModel, num_worlds: int, substeps: int) -> int:
    """Bytes the CPU backend's float64 arrays take for ``num_worlds`` worlds: the state, a state and
    the sensor values per substep, and the controls (a lower bound on what the env needs)."""
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS.value)
    per_world = (1 + substeps) * nstate + substeps * (model.nsensordata + model.nu)
    return 8 * num_worlds * per_world


def check_fits(model: mujoco.MjModel, num_worlds: int, substeps: int, available: int | None = None) -> None:
    """Refuse ``num_worlds`` worlds whose physics arrays alone would not fit in the available memory.

    Raises:
        ValueError naming num_envs, the memory it needs and the memory there is.
    """
    available = available_memory() if available is None else available
    need = cpu_batch_bytes(model, num_worlds, substeps)
    if available is not None and need > available:
        most = max(1, num_worlds * available // need)
        raise ValueError(
            f"num_envs {num_worlds} needs at least {need / GIB:.1f} GiB for its physics arrays alone; this machine "
            f"has {available / GIB:.1f} GiB available, which holds those of at most {most} envs"
        )

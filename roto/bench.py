"""Throughput benchmark: env steps/s against plain physics stepping of the same model.

CPU backend: ``efficiency = env_steps_per_s · substeps / (threads · raw_physics_steps_per_s)``,
where the raw figure is single-thread ``mj_step``; 1.0 means the env costs no more than its
physics on each thread it uses.

Warp backend: ``efficiency = env_steps_per_s · substeps / raw_physics_steps_per_s``, where the raw
figure is plain ``mujoco_warp.step`` on all B worlds of the same model and device (graph-captured
on a GPU, like the env's step); 1.0 means the env costs no more than its batched physics.
"""

from __future__ import annotations

import platform
import time
from typing import Any

import mujoco
import numpy as np
import torch

from roto.registry import make


def _random_actions(generator: torch.Generator, num_envs: int, num_actions: int, steps: int) -> torch.Tensor:
    """A new uniform target every step: the 'random' workload (steps, B, n)."""
    return torch.rand((steps, num_envs, num_actions), generator=generator) * 2.0 - 1.0


def raw_physics_seconds(
    env: Any, states: np.ndarray, ctrls: np.ndarray, substeps: int, data: mujoco.MjData | None = None
) -> float:
    """Seconds of plain single-thread ``mj_step`` (``substeps`` each) from states (n, nstate), controls (n, nu).

    ``data`` is the scratch ``MjData`` to step in (a new one if None).
    """
    model = env.model
    data = mujoco.MjData(model) if data is None else data
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS.value
    elapsed = 0.0
    for state, ctrl in zip(states, ctrls, strict=True):
        mujoco.mj_setState(model, data, state, full)
        data.ctrl[:] = ctrl
        start = time.perf_counter()
        mujoco.mj_step(model, data, nstep=substeps)
        elapsed += time.perf_counter() - start
    return elapsed


def raw_physics_steps_per_s(env: Any, states: np.ndarray, ctrls: np.ndarray, substeps: int) -> float:
    """Plain single-thread ``mj_step`` over the given states (B, nstate) and controls (B, nu)."""
    return len(states) * substeps / raw_physics_seconds(env, states, ctrls, substeps)


def _check_step_counts(steps: int, warmup: int) -> None:
    """Refuse step counts the benchmark cannot time: ``steps`` below 1, ``warmup`` below 0."""
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise ValueError(f"steps (--steps, the timed control steps) must be an integer >= 1, got {steps!r}")
    if isinstance(warmup, bool) or not isinstance(warmup, int) or warmup < 0:
        raise ValueError(f"warmup must be an integer >= 0, got {warmup!r}")


def run_bench(
    task: str = "bounce",
    robot: str = "shadow",
    num_envs: int = 256,
    threads: int = 1,
    steps: int = 200,
    warmup: int = 20,
    obs_mode: str = "blind",
    seed: int = 0,
    backend: str = "cpu",
    device: str = "cpu",
    touch: str = "binary",
) -> dict[str, Any]:
    """Measure env and raw physics throughput in one run; returns the JSON-able result. Refuses
    ``steps`` below 1 and ``warmup`` below 0 (ValueError) before any env is built."""
    _check_step_counts(steps, warmup)
    torch.set_num_threads(1)
    env = make(
        task,
        robot=robot,
        num_envs=num_envs,
        obs_mode=obs_mode,
        seed=seed,
        threads=threads,
        backend=backend,
        device=device,
        touch=touch,
    )
    generator = torch.Generator().manual_seed(seed)
    actions = _random_actions(generator, num_envs, env.num_actions, warmup + steps).to(env.device)
    env.reset()
    for t in range(warmup):
        env.step(actions[t])
    if backend == "cpu":
        env_rate, raw = _time_cpu(env, actions[warmup:])
        efficiency = env_rate * env.config.substeps / (threads * raw)
    else:
        env_rate, raw = _time_warp(env, actions[warmup:])
        efficiency = env_rate * env.config.substeps / raw
    env.backend.check_overflow()
    env.close()
    return {
        "task": task,
        "robot": robot,
        "backend": backend,
        "device": str(env.device),
        "obs_mode": obs_mode,
        "touch": touch,
        "num_envs": num_envs,
        "threads": threads,
        "substeps": env.config.substeps,
        "steps": steps,
        "env_steps_per_s": round(env_rate, 1),
        "raw_physics_steps_per_s": round(raw, 1),
        "efficiency": round(efficiency, 3),
        "machine": _machine(env.device),
        "mujoco": mujoco.__version__,
    }


def _time_cpu(env: Any, actions: torch.Tensor) -> tuple[float, float]:
    """(env steps/s, single-thread raw physics steps/s) over ``actions`` (steps, B, n), interleaved.

    After every env step, plain ``mj_step`` runs on the next eighth of the env's worlds (their
    current states and targets), rotating through all of them. Both figures thus sample the same
    stretches of time, so a slow spell of a shared machine slows both alike instead of only one.
    """
    num_envs, substeps = env.num_envs, env.config.substeps
    share = max(1, num_envs // 8)
    scratch = mujoco.MjData(env.model)
    env_seconds = raw_seconds = 0.0
    raw_steps = 0
    for t, action in enumerate(actions):
        start = time.perf_counter()
        env.step(action)
        env_seconds += time.perf_counter() - start
        first = (t * share) % num_envs
        worlds = slice(first, min(num_envs, first + share))
        states = env.backend.physics_state()[worlds]
        raw_seconds += raw_physics_seconds(env, states, env.joint_targets[worlds].numpy(), substeps, scratch)
        raw_steps += len(states) * substeps
    return num_envs * len(actions) / env_seconds, raw_steps / raw_seconds


def _synchronize(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def _time_warp(env: Any, actions: torch.Tensor) -> tuple[float, float]:
    """(env steps/s, bare ``mujoco_warp.step`` physics steps/s on all B worlds) over ``actions``."""
    _synchronize(env.device)
    start = time.perf_counter()
    for action in actions:
        env.step(action)
    _synchronize(env.device)
    env_rate = env.num_envs * len(actions) / (time.perf_counter() - start)
    return env_rate, env.backend.bare_physics_steps_per_s(len(actions))


def _machine(device: torch.device) -> str:
    cpu = f"{platform.processor() or platform.machine()}, {torch.get_num_threads()} torch thread(s)"
    if device.type == "cuda":
        return f"{torch.cuda.get_device_name(device)}; {cpu}"
    return cpu

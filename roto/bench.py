"""Throughput benchmark: env steps/s against plain single-thread ``mj_step`` of the same model.

``efficiency = env_steps_per_s · substeps / (threads · raw_physics_steps_per_s)``: 1.0 means the
env costs no more than its physics on each thread it uses.
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


def raw_physics_steps_per_s(env: Any, states: np.ndarray, ctrls: np.ndarray, substeps: int) -> float:
    """Plain single-thread ``mj_step`` over the given states (B, nstate) and controls (B, nu)."""
    model = env.model
    data = mujoco.MjData(model)
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS.value
    elapsed = 0.0
    for state, ctrl in zip(states, ctrls, strict=True):
        mujoco.mj_setState(model, data, state, full)
        data.ctrl[:] = ctrl
        start = time.perf_counter()
        mujoco.mj_step(model, data, nstep=substeps)
        elapsed += time.perf_counter() - start
    return len(states) * substeps / elapsed


def run_bench(
    task: str = "bounce",
    robot: str = "shadow",
    num_envs: int = 256,
    threads: int = 1,
    steps: int = 200,
    warmup: int = 20,
    obs_mode: str = "blind",
    seed: int = 0,
) -> dict[str, Any]:
    """Measure env and raw physics throughput in one run; returns the JSON-able result."""
    torch.set_num_threads(1)
    env = make(task, robot=robot, num_envs=num_envs, obs_mode=obs_mode, seed=seed, threads=threads)
    generator = torch.Generator().manual_seed(seed)
    actions = _random_actions(generator, num_envs, env.num_actions, warmup + steps)
    env.reset()
    for t in range(warmup):
        env.step(actions[t])
    wall = 0.0
    raw_rates = []
    sample_every = max(1, steps // 4)
    for t in range(warmup, warmup + steps):
        if (t - warmup) % sample_every == 0:
            # the raw-physics reference runs on the env's own current states and targets
            raw_rates.append(
                raw_physics_steps_per_s(env, env.backend.state.copy(), env._target.numpy(), env.config.substeps)
            )
        start = time.perf_counter()
        env.step(actions[t])
        wall += time.perf_counter() - start
    env.close()
    env_rate = num_envs * steps / wall
    raw = float(np.mean(raw_rates))
    return {
        "task": task,
        "robot": robot,
        "backend": "cpu",
        "obs_mode": obs_mode,
        "num_envs": num_envs,
        "threads": threads,
        "substeps": env.config.substeps,
        "steps": steps,
        "env_steps_per_s": round(env_rate, 1),
        "raw_physics_steps_per_s": round(raw, 1),
        "efficiency": round(env_rate * env.config.substeps / (threads * raw), 3),
        "machine": f"{platform.processor() or platform.machine()}, {torch.get_num_threads()} torch thread(s)",
        "mujoco": mujoco.__version__,
    }

"""Where a CPU env step goes, with 1 and 2 threads: physics (``backend.step``) vs the env's own work.

    python benchmarks/thread_scaling.py [--task bounce] [--robot shadow] [--num_envs 256] [--steps 100]

Both envs (1 and 2 threads, same seed, same random actions) run in one process, in alternating
blocks, so a slow spell of a shared machine hits both alike; figures are medians over the blocks.
Per control step it reports the time inside ``env.backend.step`` (the threaded ``rollout`` call
and its array copies), the rest of ``env.step`` (action checks, task, observations, resets with
their small reset ``rollout``), and single-thread ``mj_step`` on the same states (``roto bench``'s
reference). Then

    physics_scaling   = physics ms (1 thread) / physics ms (2 threads)     (2.0 = perfect)
    physics_vs_raw    = raw mj_step ms per step / physics ms, at 1 thread  (1.0 = no rollout cost)
    env_share         = env's own ms / total ms

and ``roto bench``'s 2-thread efficiency is about physics_vs_raw · physics_scaling / 2 · (1 - env_share).
Prints one JSON object.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from typing import Any

import torch

import roto
from roto.bench import raw_physics_steps_per_s


def _timed_block(env: Any, actions: torch.Tensor) -> tuple[float, float]:
    """(ms per step in ``backend.step``, ms per step elsewhere in ``env.step``) over ``actions``."""
    backend = env.backend
    physics = 0.0
    step = backend.step

    def timed_step(ctrl: torch.Tensor) -> Any:
        nonlocal physics
        start = time.perf_counter()
        out = step(ctrl)
        physics += time.perf_counter() - start
        return out

    backend.step = timed_step
    try:
        start = time.perf_counter()
        for action in actions:
            env.step(action)
        total = time.perf_counter() - start
    finally:
        del backend.step  # back to the class's method
    n = len(actions)
    return 1e3 * physics / n, 1e3 * (total - physics) / n


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--task", default="bounce")
    parser.add_argument("--robot", default="shadow")
    parser.add_argument("--num_envs", type=int, default=256)
    parser.add_argument("--steps", type=int, default=100, help="timed steps per block")
    parser.add_argument("--blocks", type=int, default=5)
    args = parser.parse_args()
    torch.set_num_threads(1)
    envs = {t: roto.make(args.task, robot=args.robot, num_envs=args.num_envs, threads=t, seed=0) for t in (1, 2)}
    num_actions = envs[1].num_actions
    generator = torch.Generator().manual_seed(0)
    warmup = 20
    actions = torch.rand((warmup + args.blocks * args.steps, args.num_envs, num_actions), generator=generator) * 2 - 1
    for env in envs.values():
        env.reset()
        for action in actions[:warmup]:
            env.step(action)
    physics: dict[int, list[float]] = {1: [], 2: []}
    own: dict[int, list[float]] = {1: [], 2: []}
    raw_ms: list[float] = []
    substeps = envs[1].config.substeps
    for block in range(args.blocks):
        block_actions = actions[warmup + block * args.steps : warmup + (block + 1) * args.steps]
        for threads, env in envs.items():
            p, o = _timed_block(env, block_actions)
            physics[threads].append(p)
            own[threads].append(o)
        env = envs[1]
        rate = raw_physics_steps_per_s(env, env.backend.physics_state(), env.joint_targets.numpy(), substeps)
        raw_ms.append(1e3 * args.num_envs * substeps / rate)
    for env in envs.values():
        env.close()
    med = statistics.median
    p1, p2, o1, o2, raw = med(physics[1]), med(physics[2]), med(own[1]), med(own[2]), med(raw_ms)
    print(
        json.dumps(
            {
                "task": args.task,
                "robot": args.robot,
                "num_envs": args.num_envs,
                "physics_ms": {"1": round(p1, 2), "2": round(p2, 2)},
                "env_own_ms": {"1": round(o1, 2), "2": round(o2, 2)},
                "raw_mj_step_ms_single_thread": round(raw, 2),
                "physics_scaling": round(p1 / p2, 3),
                "physics_vs_raw": round(raw / p1, 3),
                "env_share": {"1": round(o1 / (p1 + o1), 3), "2": round(o2 / (p2 + o2), 3)},
                "efficiency": {"1": round(raw / (p1 + o1), 3), "2": round(raw / (2 * (p2 + o2)), 3)},
            }
        )
    )


if __name__ == "__main__":
    main()

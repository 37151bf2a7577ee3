"""The single Gymnasium env's speed against its physics: ``gymnasium.make("roto/...")`` stepped by
Gymnasium's own ``benchmark_step`` (random actions, ``action_space.sample()`` included), against
plain single-thread ``mj_step`` (``roto bench``'s raw figure) on the states that env visited.

    python benchmarks/single_env.py --repeats 5 --out single_env.json

``ratio = env steps/s ÷ (raw physics steps/s ÷ substeps)``: 1.0 would mean the env costs nothing
beyond its physics. The two figures are taken in turn, ``--repeats`` times each, and their
medians reported, so a slow spell of a shared machine touches both.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import platform
import statistics
import subprocess

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium.utils.performance import benchmark_step

from roto.bench import raw_physics_steps_per_s
from roto.registry import gym_id, list_envs


def visited_states(env: gym.Env, steps: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Physics states (n, nstate) and joint targets (n, nu) the env passes through under random actions."""
    inner = env.unwrapped.env
    env.action_space.seed(seed)
    states, targets = [], []
    for _ in range(steps):
        states.append(inner.backend.physics_state()[0])
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        targets.append(inner.joint_targets[0].numpy().copy())
        if terminated or truncated:
            env.reset()
    return np.stack(states), np.stack(targets)


def measure(task: str, robot: str, repeats: int, seconds: float, seed: int = 0) -> dict:
    """Median env steps/s, raw physics steps/s and their ratio for one pair."""
    env = gym.make(gym_id(task, robot))
    env.reset(seed=seed)
    inner = env.unwrapped.env
    substeps = inner.config.substeps
    states, targets = visited_states(env, 300, seed)
    env_rates, raw_rates = [], []
    for _ in range(repeats):
        env.reset(seed=seed)
        env_rates.append(benchmark_step(env, target_duration=seconds, seed=seed))
        raw_rates.append(raw_physics_steps_per_s(inner, states, targets, substeps))
    env.close()
    env_rate, raw = statistics.median(env_rates), statistics.median(raw_rates)
    return {
        "task": task,
        "robot": robot,
        "env_steps_per_s": round(env_rate, 1),
        "raw_physics_steps_per_s": round(raw, 1),
        "substeps": substeps,
        "ratio": round(env_rate * substeps / raw, 3),
        "env_runs": [round(r, 1) for r in env_rates],
        "raw_runs": [round(r, 1) for r in raw_rates],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pairs", nargs="*", default=None, help="task:robot pairs (default: all eight)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--seconds", type=float, default=2.0, help="benchmark_step's duration per repeat")
    parser.add_argument("--out", default=None, help="also write the results as JSON here")
    args = parser.parse_args()
    pairs = [tuple(p.split(":")) for p in args.pairs] if args.pairs else list_envs()
    rows = []
    for task, robot in pairs:
        row = measure(task, robot, args.repeats, args.seconds)
        rows.append(row)
        print(json.dumps(row), flush=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    result = {
        "commit": commit,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores",
        "mujoco": mujoco.__version__,
        "repeats": args.repeats,
        "seconds": args.seconds,
        "pairs": rows,
    }
    if args.out:
        pathlib.Path(args.out).write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()

"""Peak contacts and constraint rows per world, per (robot, task): what sizes the Warp capacities.

    python benchmarks/contact_peaks.py [--num_envs 64] [--steps 600]

Each pair runs on the CPU backend under two workloads, and after every control step every world's
state is re-evaluated with ``mj_forward`` to read its ``ncon`` and ``nefc``:

* ``random``: a new uniform random action every step (the bench workload; the hand flails);
* ``held``: zero action, the default pose holding the task's balls.

Prints one JSON line per pair with the peaks; each hand's record of the pair keeps them
(``PairRecord.warp_peaks``) and ``roto.envs.capacity`` adds the margin.
"""

from __future__ import annotations

import argparse
import json

import mujoco
import torch

import roto
from roto.robots import ROBOTS
from roto.tasks import TASKS


def peaks(task: str, robot: str, num_envs: int, steps: int, workload: str, seed: int = 0) -> tuple[int, int]:
    """(max ncon, max nefc) over every world and control step of one run."""
    env = roto.make(task, robot=robot, num_envs=num_envs, seed=seed, threads=2)
    data = mujoco.MjData(env.model)
    generator = torch.Generator().manual_seed(seed)
    env.reset()
    ncon = nefc = 0
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS.value
    for _ in range(steps):
        if workload == "random":
            action = torch.rand((num_envs, env.num_actions), generator=generator) * 2 - 1
        else:
            action = torch.zeros((num_envs, env.num_actions))
        env.step(action)
        for state in env.backend.physics_state():
            mujoco.mj_setState(env.model, data, state, full)
            mujoco.mj_forward(env.model, data)
            ncon, nefc = max(ncon, data.ncon), max(nefc, data.nefc)
    env.close()
    return ncon, nefc


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--num_envs", type=int, default=64)
    parser.add_argument("--steps", type=int, default=600)
    args = parser.parse_args()
    for robot in ROBOTS:
        for task in TASKS:
            row = {"robot": robot, "task": task}
            for workload in ("random", "held"):
                ncon, nefc = peaks(task, robot, args.num_envs, args.steps, workload)
                row[f"{workload}_ncon"], row[f"{workload}_nefc"] = ncon, nefc
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()

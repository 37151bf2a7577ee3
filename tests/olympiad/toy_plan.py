"""A plan of 8 toy-env cells (tests/rl/toy_env.py): each trains in a second or two."""

from __future__ import annotations

import pathlib

from roto.olympiad.plan import load_plan
from roto.olympiad.worker import run_olympiad_worker
from tests.rl.toy_env import ToyEnv

TINY = ["network.encoder=[16]", "network.policy_head=[8]", "network.value_head=[8]", "ppo.rollouts=4", "ppo.epochs=1",
        "ppo.minibatches=2", "run.num_eval_envs=2", "run.eval_every=2", "run.checkpoint_every=1"]  # fmt: skip


def write_toy_plan(folder: pathlib.Path, updates: int = 6, seeds: tuple[int, ...] = (0, 1)) -> pathlib.Path:
    """2 tasks x 2 robots x 1 obs mode x 1 variant x ``seeds`` on 8 envs, ``updates`` updates per cell."""
    path = folder / "toy.yaml"
    tiny = "[" + ", ".join(f"'{o}'" for o in TINY) + "]"
    path.write_text(
        f"steps: {8 * 4 * updates}\neval_episodes: 3\nnum_envs: 8\nthreads: 1\n"
        f"variants:\n  ppo:\n    bounce: {{overrides: {tiny}}}\n    baoding: {{overrides: {tiny}}}\n"
        f"grids:\n  - {{tasks: [bounce, baoding], robots: [shadow, allegro], obs: [proprio], variants: [ppo], "
        f"seeds: {list(seeds)}}}\n"
    )
    return path


def toy_worker(plan_path: pathlib.Path, root: pathlib.Path, heartbeat: float = 5.0) -> int:
    """An Olympiad worker on the toy env (a process target: importable, no closure)."""
    return run_olympiad_worker(load_plan(str(plan_path)), str(root), heartbeat=heartbeat, env_factory=ToyEnv)

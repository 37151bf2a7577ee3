"""A sweep on the toy env (tests/rl/toy_env.py): trials of a few seconds."""

from __future__ import annotations

import pathlib

from roto.sweep.settings import SweepSettings
from roto.sweep.worker import run_worker
from tests.rl.toy_env import ToyEnv

TOY_OVERRIDES = (
    "network.encoder=[16]",
    "network.policy_head=[8]",
    "network.value_head=[8]",
    "ppo.rollouts=4",
    "ppo.minibatches=2",
    "run.num_eval_envs=2",
    "run.eval_every=2",
    "run.checkpoint_every=1",
)
TOY_SPACE = """
parameters:
  ppo.lr: {type: float, low: 1.0e-4, high: 3.0e-3, log: true}
  ppo.epochs: {type: int, low: 1, high: 3}
  env.action_smoothing: {type: categorical, choices: [0.5, 1.0]}
"""


def toy_settings(root: pathlib.Path, trials: int, updates: int = 6, **changes) -> SweepSettings:
    """A study of ``trials`` toy trials of ``updates`` updates each (8 envs x 4 rollouts per update)."""
    space = root / "toy_space.yaml"
    space.write_text(TOY_SPACE)
    values = dict(study="toy", obs="proprio", space=str(space), trials=trials, startup=2, steps=32 * updates,
                  num_envs=8, overrides=TOY_OVERRIDES, root=str(root), heartbeat=5.0)  # fmt: skip
    return SweepSettings(**{**values, **changes})


def toy_worker(settings: SweepSettings) -> int:
    """A worker on the toy env (a process target: importable, no closure)."""
    return run_worker(settings, env_factory=ToyEnv)

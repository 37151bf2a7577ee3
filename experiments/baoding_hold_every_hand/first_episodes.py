"""How long an untrained policy's first training episodes last, per hand and seed, with and
without the hold-pose start: one episode in each of 128 training envs of a fresh trainer of the
config (its aids on, its policy std), nothing learned.

    python experiments/baoding_hold_every_hand/first_episodes.py [robot ...]
    python experiments/baoding_hold_every_hand/first_episodes.py --task bounce --obs state \
        --agent_cfg bounce_cpu_quickstart [robot ...]
    python experiments/baoding_hold_every_hand/first_episodes.py --override network.max_log_std=-1.897 \
        --override network.init_log_std=-1.897 allegro   # under another policy std

Prints one line per (robot, start): the seeds' mean first-episode lengths in control steps.
"""

import argparse
import tempfile

import torch

from roto.envs.episodes import first_episodes
from roto.rl.run_spec import build_run_spec
from roto.rl.runner import Trainer

SEEDS = range(5)


def first_episode_length(
    task: str, robot: str, obs: str, agent_cfg: str, seed: int, hold: bool, overrides: tuple[str, ...] = ()
) -> float:
    """Mean over the training envs of the first episode's length (steps) of a fresh trainer of
    ``agent_cfg`` with ``overrides``."""
    overrides = [*overrides, f"network.start_at_hold={str(hold).lower()}"]
    spec = build_run_spec(task, robot, obs, agent_cfg, overrides, 1, num_envs=128, threads=1, seed=seed)
    with tempfile.TemporaryDirectory() as run_dir, Trainer(spec, run_dir, tensorboard=False) as trainer:
        obs, _ = trainer.env.reset(seed=seed)
        with torch.no_grad():
            return float(first_episodes(trainer.env, trainer.alg.act, obs)["length"].mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("robots", nargs="*", default=["shadow", "shadow_lite", "allegro", "orca"])
    parser.add_argument("--task", default="baoding")
    parser.add_argument("--obs", default="blind")
    parser.add_argument("--agent_cfg", default="baoding_cpu")
    parser.add_argument("--override", action="append", default=[], help="a config override, as roto train's")
    args = parser.parse_args()
    torch.set_num_threads(1)
    for robot in args.robots:
        for hold in (False, True):
            lengths = [
                first_episode_length(args.task, robot, args.obs, args.agent_cfg, s, hold, tuple(args.override))
                for s in SEEDS
            ]
            shown = ", ".join(f"{value:.0f}" for value in lengths)
            print(f"{robot:12s} start_at_hold={hold!s:5s} first episodes by seed {list(SEEDS)}: {shown}", flush=True)


if __name__ == "__main__":
    main()

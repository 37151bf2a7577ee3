"""What each auxiliary loss (and a privileged critic) adds to a PPO update, in one process.

    python benchmarks/aux_cost.py [--updates 6] [--num_envs 128] [--threads 2] [--torch_threads 2]

Trains blind Shadow Bounce with ``make train``'s agent config for a few updates per variant, one
variant after another, and prints one JSON line per variant: the median over the updates after the
first of the seconds spent simulating, in policy inference and in the update, and env steps/s
(rollout + update). Evaluation is off (``run.eval_every`` beyond the run). Run it on a quiet host.
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile

import torch

from roto.envs.config import EnvConfig
from roto.rl.config_files import load_agent_config
from roto.rl.run_dir import read_scalars
from roto.rl.run_spec import RunSpec
from roto.rl.runner import Trainer

FD = "weight: 0.0021, lr: 1.5e-5, seq_length: 8"
VARIANTS = {
    "ppo": [],
    "forward_dynamics (all sequences)": [f"ssl.forward_dynamics={{{FD}}}"],
    "forward_dynamics_memory (all sequences)": [f"ssl.forward_dynamics_memory={{{FD}}}"],
    "forward_dynamics (max_sequences 292)": [f"ssl.forward_dynamics={{{FD}, max_sequences: 292}}"],
    "forward_dynamics_memory (max_sequences 292)": [f"ssl.forward_dynamics_memory={{{FD}, max_sequences: 292}}"],
    "tactile_reconstruction": ["ssl.tactile_reconstruction={weight: 0.086, lr: 1.1e-4}"],
    "privileged_critic": ["network.critic=[tactile, proprio, privileged]"],
}


def measure(overrides: list[str], args: argparse.Namespace, run_dir: str) -> dict[str, float]:
    """Median per-update timings of a short run with ``overrides``."""
    env = EnvConfig(task="bounce", robot="shadow", num_envs=args.num_envs, threads=args.threads, seed=0)
    agent = load_agent_config("bounce", "bounce_cpu", [*overrides, "run.eval_every=100000"])
    steps = agent.ppo.rollouts * args.num_envs * args.updates
    trainer = Trainer(RunSpec(env=env, agent=agent, steps=steps), run_dir, tensorboard=False)
    trainer.train(progress=False)
    trainer.env.close()
    trainer.evaluator.env.close()
    series = read_scalars(run_dir)
    tags = ("perf/simulation_s", "perf/inference_s", "perf/update_s", "perf/steps_per_s")
    return {tag.removeprefix("perf/"): round(statistics.median(series[tag][1][1:]), 3) for tag in tags}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--updates", type=int, default=6)
    parser.add_argument("--num_envs", type=int, default=128)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--torch_threads", type=int, default=2)
    args = parser.parse_args()
    torch.set_num_threads(args.torch_threads)
    with tempfile.TemporaryDirectory() as tmp:
        for i, (name, overrides) in enumerate(VARIANTS.items()):
            print(json.dumps({"variant": name, **measure(overrides, args, f"{tmp}/{i}")}), flush=True)


if __name__ == "__main__":
    main()

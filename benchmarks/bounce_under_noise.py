"""How long the ball stays up, and how often it bounces, when Gaussian noise is added to simple Bounce policies.

    python benchmarks/bounce_under_noise.py [--robots shadow shadow_lite allegro orca] [--envs 64] [--seed 1]

A PPO agent starts with actions of standard deviation 1 in the normalised action space ([-1, 1]),
so what such noise does on a hand shapes what the first policies are rewarded for. For each robot
and each policy below, one episode per env (the first, as ``roto eval`` counts them); prints one
line per (robot, policy) and, with ``--json``, writes every figure there:

* ``mid``: action 0 (every target at the middle of its control range);
* ``hold``: the default (cupped) pose, as ``RotoEnv.hold_action``;
* ``noise``: N(0, 1) actions clipped to [-1, 1], the untrained agent's exploration;
* ``scripted``: the robot's scripted Bounce reference (``roto.scripted``);
* ``hold+s`` and ``scripted+s``: those policies plus N(0, s²) noise, clipped.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable

import torch

from roto.envs.episodes import first_episodes
from roto.registry import make
from roto.scripted import SCRIPTS, ScriptedBounce

POLICIES = {
    "mid": ("mid", 0.0),
    "hold": ("hold", 0.0),
    "hold+0.3": ("hold", 0.3),
    "noise": ("mid", 1.0),
    "scripted": ("scripted", 0.0),
    "scripted+0.3": ("scripted", 0.3),
    "scripted+1": ("scripted", 1.0),
}
"""Policy name -> (base policy, std of the Gaussian noise added to its actions)."""


def noisy(act: Callable[[dict], torch.Tensor], std: float, generator: torch.Generator) -> Callable:
    """``act`` plus N(0, std²) noise per action, clipped to [-1, 1]."""

    def noisy_act(obs: dict) -> torch.Tensor:
        action = act(obs)
        noise = torch.randn(action.shape, generator=generator, dtype=action.dtype)
        return (action + std * noise).clamp(-1.0, 1.0)

    return noisy_act


def run_policy(robot: str, policy: str, envs: int, seed: int) -> dict[str, float]:
    """Mean episode length (steps) and bounces per episode of ``policy`` on ``robot``'s Bounce."""
    env = make("bounce", robot, num_envs=envs, obs_mode="state", seed=seed)
    obs, _ = env.reset()
    generator = torch.Generator().manual_seed(seed)
    scripted = ScriptedBounce(env, SCRIPTS[robot])
    name, noise_std = POLICIES[policy]
    base: Callable[[dict], torch.Tensor] = {
        "mid": lambda o: torch.zeros(envs, env.num_actions),
        "hold": lambda o: env.hold_action().expand(envs, -1),
        "scripted": scripted,
    }[name]
    act = noisy(base, noise_std, generator) if noise_std else base
    result = first_episodes(env, act, obs, 1, on_done=scripted.reset)
    return {"length": float(result["length"].mean()), "bounces": float(result["bounces"].mean())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=sorted(SCRIPTS))
    parser.add_argument("--envs", type=int, default=64)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args()
    unknown = sorted(set(args.robots) - set(SCRIPTS))
    if unknown:
        parser.error(f"no Bounce script for {unknown}; choose from {sorted(SCRIPTS)}")
    figures: dict[str, dict[str, dict[str, float]]] = {}
    for robot in args.robots:
        figures[robot] = {}
        for policy in POLICIES:
            figures[robot][policy] = run_policy(robot, policy, args.envs, args.seed)
            row = figures[robot][policy]
            print(f"{robot:12s} {policy:13s} length {row['length']:6.1f}  bounces {row['bounces']:5.2f}", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"envs": args.envs, "seed": args.seed, "figures": figures}, f, indent=1)


if __name__ == "__main__":
    main()

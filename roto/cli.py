"""``roto`` command line: ``roto list``, ``roto bench``, ``roto demo``."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence


def _add_env_args(parser: argparse.ArgumentParser, num_envs: int) -> None:
    parser.add_argument("--task", default="bounce", help="task name: bounce, baoding (default: bounce)")
    parser.add_argument("--robot", default="shadow", help="robot name (default: shadow)")
    parser.add_argument("--num_envs", "--num-envs", dest="num_envs", type=int, default=num_envs)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1, help="C threads stepping the worlds (CPU backend)")
    parser.add_argument("--headless", action="store_true", help="accepted for Isaac Lab compatibility; no effect")


def _cmd_list(args: argparse.Namespace) -> int:
    import roto
    from roto.registry import gym_id

    print(f"{'task':<9} {'robot':<8} {'gymnasium id':<26} {'actions':>7} {'frame (blind)':>13} {'stacked':>8}")
    for task, robot in roto.list_envs():
        env = roto.make(task, robot=robot, num_envs=1)
        frame = sum(env.frame_sizes.values())
        stacked = frame * env.config.frame_stack
        print(f"{task:<9} {robot:<8} {gym_id(task, robot):<26} {env.num_actions:>7} {frame:>13} {stacked:>8}")
        env.close()
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from roto.bench import run_bench

    result = run_bench(
        task=args.task,
        robot=args.robot,
        num_envs=args.num_envs,
        threads=args.threads,
        steps=args.steps,
        obs_mode=args.obs_mode,
        seed=args.seed,
    )
    if args.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key:>24}: {value}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from roto.scripted import run_scripted_bounce

    stats = run_scripted_bounce(num_envs=args.num_envs, seed=args.seed, episodes=args.episodes, progress=True)
    print(json.dumps(stats))
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The ``roto`` argument parser."""
    parser = argparse.ArgumentParser(prog="roto", description="roto: the Robot Tactile Olympiad on MuJoCo")
    sub = parser.add_subparsers(dest="command", required=True)

    p_list = sub.add_parser("list", help="every (task, robot) pair with its observation and action sizes")
    p_list.set_defaults(func=_cmd_list)

    p_bench = sub.add_parser("bench", help="env throughput vs plain single-thread mj_step of the same model")
    _add_env_args(p_bench, num_envs=256)
    p_bench.add_argument("--steps", type=int, default=200, help="timed control steps (default: 200)")
    p_bench.add_argument("--obs_mode", "--obs-mode", dest="obs_mode", default="blind")
    p_bench.add_argument("--json", action="store_true", help="print one JSON object")
    p_bench.set_defaults(func=_cmd_bench)

    p_demo = sub.add_parser("demo", help="run the scripted Bounce policy and print its bounces per episode")
    _add_env_args(p_demo, num_envs=8)
    p_demo.add_argument("--episodes", type=int, default=1, help="episodes per env (default: 1)")
    p_demo.set_defaults(func=_cmd_demo)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``roto`` command."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except (ValueError, TypeError) as error:
        print(f"roto {args.command}: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())

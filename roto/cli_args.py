"""Flags that several ``roto`` commands share."""

from __future__ import annotations

import argparse


def add_env_args(parser: argparse.ArgumentParser, num_envs: int) -> None:
    """The env flags shared by the commands that build envs (task, robot, worlds, seed, backend)."""
    parser.add_argument("--task", default="bounce", help="task name: bounce, baoding (default: bounce)")
    parser.add_argument("--robot", default="shadow", help="hand: shadow, shadow_lite, allegro, orca (default: shadow)")
    parser.add_argument(
        "--num_envs",
        "--num-envs",
        dest="num_envs",
        type=int,
        default=num_envs,
        help=f"worlds stepped side by side (default: {num_envs})",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the envs' starts, and in roto train of the agent's weights too (default: 0)",
    )
    parser.add_argument("--threads", type=int, default=1, help="C threads stepping the worlds (CPU backend)")
    parser.add_argument("--backend", default="cpu", help="physics backend: cpu (default) or warp (MuJoCo Warp)")
    parser.add_argument("--device", default="cpu", help="cpu (default), or cuda[:k] with --backend warp")
    parser.add_argument("--headless", action="store_true", help="accepted for Isaac Lab compatibility; no effect")


def env_flags(args: argparse.Namespace) -> dict:
    """The env flags of ``add_env_args`` and ``add_touch_arg`` a command was given, as the keyword
    arguments of the env builders (num_envs, seed, backend, device, threads, touch)."""
    names = ("num_envs", "seed", "backend", "device", "threads", "touch")
    return {name: getattr(args, name) for name in names}


def add_checkpoint_arg(parser: argparse.ArgumentParser) -> None:
    """``--checkpoint``, required, of the commands that load a trained policy (eval, play)."""
    parser.add_argument(
        "--checkpoint",
        required=True,
        help="a checkpoint roto train wrote (<run_dir>/checkpoints/best.pt); its task, hand, obs mode and "
        "config come with it",
    )


def add_touch_arg(parser: argparse.ArgumentParser) -> None:
    """``--touch``: the tactile signal of the envs a command builds."""
    parser.add_argument(
        "--touch",
        default="binary",
        help="tactile signal: binary (a touch bit per link, the benchmark's; default), force "
        "(log(1 + |F| / 0.1 N) of each link's net contact force) or taxels (the link bits, then a bit "
        "per taxel of the fingertip pads and the palm)",
    )


class _NotGiven:
    """The default of every option while ``options_given`` parses: a value no command line makes."""


def options_given(parser: argparse.ArgumentParser, argv: list[str]) -> set[str]:
    """The destinations of the options and positionals that ``argv`` sets itself (not by default).

    ``parser`` must be a fresh parser of its own: its defaults are replaced by a marker, so only
    what ``argv`` names holds another value."""
    not_given = _NotGiven()
    parser.set_defaults(**{dest: not_given for dest in vars(parser.parse_args([]))})
    given = vars(parser.parse_args(argv))
    return {dest for dest, value in given.items() if value is not not_given and value != []}

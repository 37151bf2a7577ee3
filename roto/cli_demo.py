"""``roto demo``: a task's reference controller (the scripted Bounce policy, or Baoding's predictive sampling)."""

from __future__ import annotations

import argparse
import contextlib
import json
import pathlib
import sys

from roto.cli_args import add_env_args
from roto.cli_errors import check_output_path, parents_made


def _cmd_demo(args: argparse.Namespace) -> int:
    from roto.registry import get_task

    task = get_task(args.task).name
    if task == "baoding":
        return _demo_baoding(args)
    from roto.scripted import run_scripted_bounce

    if args.preswap_out is not None or args.preswap_leads is not None or args.turn_weight is not None:
        raise ValueError(
            "--preswap_out, --preswap_leads and --turn_weight are for --task baoding (the Bounce script makes no swaps)"
        )
    stats = run_scripted_bounce(
        robot=args.robot,
        num_envs=args.num_envs,
        seed=args.seed,
        episodes=args.episodes,
        progress=True,
        backend=args.backend,
        device=args.device,
    )
    print(json.dumps(stats))
    return 0


def _demo_baoding(args: argparse.Namespace) -> int:
    from roto.reference.baoding_controller import PRESWAP_LEAD, run_reference_baoding
    from roto.reference.baoding_cost import BaodingCostWeights

    if args.preswap_leads is not None and args.preswap_out is None:
        raise ValueError(f"--preswap_leads {args.preswap_leads} records states for --preswap_out; give that file too")
    if args.backend != "cpu":
        raise ValueError(f"backend {args.backend!r}: the Baoding reference controller plans on 'cpu' only")
    if args.turn_weight is not None and not args.turn_weight >= 0:
        raise ValueError(f"--turn_weight {args.turn_weight}: must be a weight >= 0 (0: off, no direction)")
    out = preswap_file(args.preswap_out) if args.preswap_out else None  # before the episodes, which take minutes
    with parents_made(out) if out is not None else contextlib.nullcontext():
        stats = run_reference_baoding(
            robot=args.robot,
            episodes=args.episodes,
            seed=args.seed,
            threads=args.threads,
            preswap_path=out,
            preswap_leads=tuple(args.preswap_leads or (PRESWAP_LEAD,)),
            progress=True,
            weights=BaodingCostWeights(turn=args.turn_weight or 0.0),
        )
    print(json.dumps(stats))
    if out is not None:
        print(f"wrote {out}", file=sys.stderr)
    return 0


def preswap_file(path: str) -> pathlib.Path:
    """The ``.npz`` that ``--preswap_out PATH`` writes: PATH, with ``.npz`` appended when it lacks it (as
    NumPy appends it); refused, before any episode, when PATH or that file is a directory or cannot be
    written (``check_output_path``)."""
    check_output_path(path, "--preswap_out", example="preswap.npz")
    out = pathlib.Path(path)
    if out.suffix != ".npz":
        out = out.with_name(out.name + ".npz")
        check_output_path(out, f"--preswap_out {path!r} (.npz appended):", example="preswap.npz")
    return out


def add_demo_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``roto demo``."""
    p_demo = sub.add_parser(
        "demo",
        help="run a task's reference controller: the scripted Bounce policy (bounces per episode) or, with "
        "--task baoding, predictive sampling over the true dynamics (rotations per episode; slow: about a "
        "minute per episode on 2 threads)",
    )
    add_env_args(p_demo, num_envs=8)
    p_demo.add_argument(
        "--episodes", type=int, default=1, help="episodes per env (Baoding: episodes of its one world; default: 1)"
    )
    p_demo.add_argument(
        "--preswap_out",
        "--preswap-out",
        dest="preswap_out",
        default=None,
        help="Baoding: write the states recorded just before each swap to this .npz file (.npz is appended "
        "to a name without it; missing folders are created; checked before the first episode)",
    )
    p_demo.add_argument(
        "--preswap_leads",
        "--preswap-leads",
        dest="preswap_leads",
        type=int,
        nargs="+",
        default=None,
        help="Baoding: the control steps before each swap at which --preswap_out records a state (default: 10, "
        "1/6 s; e.g. 10 20 30 40 50 60: the last second before each swap, back past the swap before it)",
    )
    p_demo.add_argument(
        "--turn_weight",
        "--turn-weight",
        dest="turn_weight",
        type=float,
        default=None,
        help="Baoding: weight of the turn the balls' axis still has to go counter-clockwise (seen from above) in "
        "the planner's cost, so that it carries the balls round one way instead of swinging them (default: 0, "
        "off: roto's swap rule has no direction)",
    )
    p_demo.set_defaults(func=_cmd_demo)

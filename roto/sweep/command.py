"""``roto sweep``: run a study's workers; ``roto sweep export`` and ``roto sweep show``."""

from __future__ import annotations

import argparse
import json
import sys

from roto.cli_errors import check_output_path
from roto.jobs.flags import add_worker_flags, check_worker_flags
from roto.sweep.settings import sweep_defaults

STORAGE_HELP = (
    "database URL (postgresql://...) or a journal file's path (*.log); default: <root>/<study>/journal.log. "
    "env:NAME reads it from environment variable NAME (as the workers --workers starts do, so that no "
    "password shows in their command lines)"
)

DEFAULTS = sweep_defaults()
"""The flags' defaults: ``SweepSettings``' own, written once."""

RUN_FLAGS = (
    "task",
    "robot",
    "obs",
    "agent_cfg",
    "space",
    "objective",
    "trials",
    "startup",
    "steps",
    "warmup_steps",
    "num_envs",
    "threads",
    "root",
    "storage",
    "heartbeat",
)
"""The ``SweepSettings`` fields the command line sets (besides the study name and overrides)."""


def _study_args(parser: argparse.ArgumentParser, required: bool) -> None:
    parser.add_argument("--study", required=required, help="study name (its folder: <root>/<study>)")
    parser.add_argument("--root", default=DEFAULTS["root"], help="folder of the studies' folders (default %(default)s)")
    parser.add_argument("--storage", default=DEFAULTS["storage"], help=STORAGE_HELP)


def add_sweep_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``roto sweep`` and its ``export`` and ``show`` subcommands."""
    p = sub.add_parser("sweep", help="tune an agent with Optuna (TPE, median pruning), on one or many machines")
    _search_args(p)
    _worker_args(p)
    _study_args(p, required=False)
    p.set_defaults(func=cmd_sweep)
    actions = p.add_subparsers(dest="sweep_command", metavar="{export,show}")
    export = actions.add_parser("export", help="write the best trial as an agent config for roto train --agent_cfg")
    _study_args(export, required=True)
    export.add_argument("--out", required=True, help="YAML file to write")
    export.add_argument("--trial", type=int, default=None, help="export this complete trial instead of the best")
    export.set_defaults(func=cmd_export)
    show = actions.add_parser("show", help="print the trials table and the parameter importances")
    _study_args(show, required=True)
    show.set_defaults(func=cmd_show)


def _search_args(p: argparse.ArgumentParser) -> None:
    """What the study searches and trains: the ``SweepSettings`` of its identity."""
    p.add_argument("--task", default=DEFAULTS["task"])
    p.add_argument("--robot", default=DEFAULTS["robot"])
    p.add_argument("--obs", default=DEFAULTS["obs"], help="blind, state or proprio")
    p.add_argument(
        "--agent_cfg", "--agent-cfg", dest="agent_cfg", default=DEFAULTS["agent_cfg"], help="base agent config"
    )
    p.add_argument(
        "--space",
        default=DEFAULTS["space"],
        help="search space: a name in roto/configs/sweep/ (default %(default)s) or a YAML file",
    )
    p.add_argument(
        "--objective",
        default=DEFAULTS["objective"],
        help="what trials maximise: the best evaluation's mean return (default), 'metric' (the task's "
        "headline metric, Baoding: rotations), or another metric the task's evaluations report "
        "(Baoding: round_rotations, the rotations its pair's net turning backs), with the return "
        "breaking ties",
    )
    p.add_argument("--trials", type=int, default=DEFAULTS["trials"], help="trials that finish (complete or pruned)")
    p.add_argument(
        "--startup", type=int, default=DEFAULTS["startup"], help="random start-up trials (also the pruner's wait)"
    )
    p.add_argument("--steps", type=int, default=DEFAULTS["steps"], help="env steps per trial")
    p.add_argument(
        "--warmup_steps", type=int, default=DEFAULTS["warmup_steps"], help="env steps before pruning (default steps/5)"
    )
    p.add_argument("--num_envs", type=int, default=DEFAULTS["num_envs"])
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="section.key=value",
        help="override every trial gets (env.num_envs=64, ppo.gamma=0.99); repeatable",
    )


def _worker_args(p: argparse.ArgumentParser) -> None:
    """How this machine's workers run the study."""
    p.add_argument("--threads", type=int, default=DEFAULTS["threads"], help="C threads stepping each worker's envs")
    add_worker_flags(p, "trial")
    p.add_argument(
        "--enqueue_base",
        "--enqueue-base",
        dest="enqueue_base",
        action="store_true",
        help="a new study's first trial: the base config's values of the searched parameters",
    )


def cmd_sweep(args: argparse.Namespace) -> int:
    """Run ``--workers`` workers on the study until it has its trials."""
    import torch

    from roto.jobs.claims import launch_workers
    from roto.jobs.storage import reclaim_now, resolve_storage, storage_in_environment
    from roto.sweep.settings import SweepSettings
    from roto.sweep.space import load_space
    from roto.sweep.study import enqueue_base, open_study
    from roto.sweep.worker import run_worker

    args.storage = resolve_storage(args.storage)
    if args.study is None:
        raise ValueError("--study is required: the study's name (workers with the same name join one study)")
    values = {name: getattr(args, name) for name in RUN_FLAGS}
    settings = SweepSettings(study=args.study, overrides=tuple(args.overrides), **values)
    check_worker_flags(args)
    check_output_path(args.root, "--root", kind="dir")
    if args.enqueue_base:  # before any worker draws a trial
        space = load_space(settings.space, settings.base_env(), settings.agent_cfg, settings.overrides)
        study = open_study(settings)[0]
        if study.trials:  # the same command that started the study continues it
            print(
                f"--enqueue_base: study {settings.study!r} already has {len(study.trials)} trials, so the base "
                "config (only ever a new study's first trial) is not enqueued again; continuing the study",
                file=sys.stderr,
            )
        else:
            inside, outside = enqueue_base(study, settings, space)
            print(
                f"enqueued the base config as the first trial: {inside}"
                + (f"; outside the space, drawn instead: {outside}" if outside else ""),
                file=sys.stderr,
            )
    if args.workers > 1:
        load_space(settings.space, settings.base_env(), settings.agent_cfg, settings.overrides)  # before creating
        study, storage = open_study(settings)  # create it once, so the workers only join
        if args.reclaim_now:  # here, once: a worker reclaiming would take its siblings' fresh claims
            reclaim_now(study, storage)
        with storage_in_environment(args.storage) as storage_argv:  # never on argv: /proc/PID/cmdline is public
            return launch_workers("sweep", args.workers, _worker_argv(args) + storage_argv)
    torch.set_num_threads(args.torch_threads)
    finished = run_worker(settings, reclaim=args.reclaim_now)
    print(json.dumps({"study": settings.study, "finished_by_this_worker": finished}))
    return 0


def _worker_argv(args: argparse.Namespace) -> list[str]:
    """A worker's arguments but ``--storage`` (which reaches it through the environment)."""
    argv = ["--study", args.study, "--torch_threads", str(args.torch_threads)]
    for name in RUN_FLAGS:
        value = getattr(args, name)
        if value is not None and name != "storage":
            argv += [f"--{name}", str(value)]
    for item in args.overrides:
        argv += ["--set", item]
    return argv


def cmd_export(args: argparse.Namespace) -> int:
    """Write the best trial's agent config."""
    from roto.jobs.storage import resolve_storage
    from roto.sweep.report import export_best

    print(json.dumps(export_best(args.study, args.root, resolve_storage(args.storage), args.out, args.trial)))
    return 0


def cmd_show(args: argparse.Namespace) -> int:
    """Print the study's trials and importances."""
    from roto.jobs.storage import resolve_storage
    from roto.sweep.report import show

    sys.stdout.write(show(args.study, args.root, resolve_storage(args.storage)) + "\n")
    return 0

"""The flags every command that runs jobs from the queue shares (``roto sweep``, ``roto olympiad``)."""

from __future__ import annotations

import argparse

from roto.value_checks import check_count

HEARTBEAT_S = 30.0
"""Seconds between a running job's heartbeats; a job silent for 4 of them is declared dead."""


def add_worker_flags(parser: argparse.ArgumentParser, job: str) -> None:
    """``--workers``, ``--torch_threads``, ``--heartbeat`` and ``--reclaim-now``; ``job`` names what a
    worker runs in the help (a trial, a cell)."""
    parser.add_argument("--workers", type=int, default=1, help="worker processes to run here (default 1)")
    parser.add_argument("--torch_threads", type=int, default=1, help="torch threads of each worker's update")
    parser.add_argument(
        "--heartbeat", type=float, default=HEARTBEAT_S, help=f"seconds between a running {job}'s heartbeats"
    )
    parser.add_argument(
        "--reclaim-now",
        "--reclaim_now",
        dest="reclaim_now",
        action="store_true",
        help=f"first fail and retry every running {job} (only when no other worker is alive)",
    )


def check_worker_flags(args: argparse.Namespace) -> None:
    """ValueError naming the first of ``add_worker_flags``' numbers out of its range (before a study is
    made or a worker starts)."""
    check_count("--workers", args.workers, 1)
    check_count("--torch_threads", args.torch_threads, 1)
    if not args.heartbeat > 0:  # also refuses nan
        raise ValueError(f"--heartbeat must be a number of seconds > 0, got {args.heartbeat}")

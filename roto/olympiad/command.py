"""``roto olympiad PLAN`` (train and evaluate a plan's cells) and ``roto results`` (its tables and plots)."""

from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
from typing import TYPE_CHECKING

from roto.cli_errors import check_output_path
from roto.jobs.flags import add_worker_flags, check_worker_flags
from roto.olympiad.submission_command import add_results_submission_flags, add_submit_parser, cmd_check
from roto.sweep.command import STORAGE_HELP

if TYPE_CHECKING:
    from roto.olympiad.plan import Plan
    from roto.tasks.base import Task


def add_olympiad_parsers(sub: argparse._SubParsersAction) -> None:
    """Register ``roto olympiad`` and ``roto results``."""
    p = sub.add_parser("olympiad", help="train and evaluate a plan of hands x tasks x obs modes x agents x seeds")
    p.add_argument("plan", help="a packaged plan (benchmark, paper, smoke) or a plan YAML file")
    p.add_argument("--root", default="runs/olympiad", help="where run directories go (<root>/<plan>/<cell>)")
    p.add_argument("--results", default=None, help="folder of the cells' summaries (default <root>/<plan>/results)")
    p.add_argument("--storage", default=None, help=STORAGE_HELP)
    add_worker_flags(p, "cell")
    p.add_argument(
        "--threads",
        type=int,
        default=None,
        help="C threads stepping each worker's envs (default: the plan's; not part of a cell)",
    )
    p.add_argument(
        "--dry-run",
        "--dry_run",
        dest="dry_run",
        action="store_true",
        help="list the cells, which are done or stale (trained otherwise than the plan now says), and the "
        "time left; train nothing",
    )
    p.add_argument(
        "--only",
        nargs="+",
        default=(),
        metavar="PATTERN",
        help="train (or list) only the cells whose names match one of these patterns ('bounce-*', "
        "'*-state-*', '*-seed2'); the plan's other cells stay for workers without --only",
    )
    p.add_argument(
        "--adopt",
        nargs=2,
        metavar=("PLAN", "RESULTS"),
        default=None,
        help="count the finished cells of another plan (its summaries in RESULTS) that train exactly "
        "a cell of this one as that cell: copy them into --results, and exit; train nothing",
    )
    p.set_defaults(func=cmd_olympiad)
    r = sub.add_parser("results", help="tables (markdown, CSV) and learning curves of an Olympiad's cells")
    r.add_argument(
        "source", nargs="?", help="a plan's name or file (its default results folder), or a folder of summaries"
    )
    r.add_argument("--out", default=None, help="folder to write results.md, results_*.csv and curves_*.png into")
    r.add_argument("--root", default="runs/olympiad")
    r.add_argument(
        "--plan", default=None, help="with a folder of summaries: the plan whose configs name its columns and manifest"
    )
    r.add_argument(
        "--pages",
        nargs="+",
        default=None,
        metavar="PAGE",
        help="refresh the generated tables of these markdown pages (docs/results.md, README.md) and exit",
    )
    add_results_submission_flags(r)
    r.set_defaults(func=cmd_results)
    add_submit_parser(sub)


def _results_dir(args: argparse.Namespace, plan_name: str) -> pathlib.Path:
    return pathlib.Path(args.results) if args.results else pathlib.Path(args.root) / plan_name / "results"


def cmd_olympiad(args: argparse.Namespace) -> int:
    """Run (or with --dry-run list) the plan's cells."""
    import torch

    from roto.jobs.claims import launch_workers
    from roto.jobs.storage import reclaim_now, resolve_storage, storage_in_environment
    from roto.olympiad.plan import load_plan, select_cells
    from roto.olympiad.staleness import refuse_stale, retrain_remedy
    from roto.olympiad.worker import enqueue_missing, open_olympiad, run_olympiad_worker

    args.storage = resolve_storage(args.storage)
    plan = load_plan(args.plan)  # checked before anything runs or is written
    if args.threads is not None:
        if args.threads < 1:
            raise ValueError(f"--threads must be >= 1, got {args.threads}")
        plan = dataclasses.replace(plan, threads=args.threads)
    chosen = select_cells(plan, args.only)  # a pattern that matches no cell stops here, before anything runs
    results = _results_dir(args, plan.name)
    check_output_path(args.root, "--root", kind="dir")  # not after hours of training, at the first summary
    check_output_path(results, "--results", kind="dir")
    if args.adopt:
        from roto.olympiad.adopt import adopt_cells

        source_plan, source_results = load_plan(args.adopt[0]), pathlib.Path(args.adopt[1])
        adopted = adopt_cells(source_plan, source_results, plan, results)
        print(json.dumps({"plan": plan.name, "adopted": adopted, "from": source_plan.name, "results": str(results)}))
        return 0
    check_worker_flags(args)
    if args.dry_run:
        print(dry_run_report(chosen, args.root, results, args.storage, args.workers, plan if args.only else None))
        return 0
    if args.workers > 1:
        refuse_stale(chosen, results, retrain_remedy(plan, args.root))  # before the study is made: nothing changed
        # create the study and enqueue the cells once, so the workers only join and claim
        study, storage = open_olympiad(plan, args.root, args.storage)
        if args.reclaim_now:  # here, once: a worker reclaiming would take its siblings' fresh claims
            reclaim_now(study, storage)
        enqueue_missing(study, chosen, results)
        argv = [
            args.plan,
            "--root",
            args.root,
            "--results",
            str(results),
            "--heartbeat",
            str(args.heartbeat),
            "--torch_threads",
            str(args.torch_threads),
            "--threads",
            str(plan.threads),
            *(["--only", *args.only] if args.only else []),
        ]
        with storage_in_environment(args.storage) as storage_argv:  # never on argv: /proc/PID/cmdline is public
            return launch_workers("olympiad", args.workers, argv + storage_argv)
    torch.set_num_threads(args.torch_threads)
    finished = run_olympiad_worker(
        plan, args.root, results, args.storage, args.heartbeat, reclaim=args.reclaim_now, only=args.only
    )
    print(json.dumps({"plan": plan.name, "finished_by_this_worker": finished, "results": str(results)}))
    return 0


def headline_so_far(records: list[dict], metric: str, path_metrics: tuple[str, ...] = ()) -> str:
    """``; last evaluation X <metric> (<other measure> P, ...), best Y at Z M`` from a run's
    evaluation records ("" without the metric; each other measure, ``path_metrics``, only where the
    last record has it)."""
    scored = [r for r in records if f"{metric}_mean" in r]
    if not scored:
        return ""
    last, best = scored[-1], max(scored, key=lambda r: r[f"{metric}_mean"])
    paths = ", ".join(f"{name} {last[f'{name}_mean']:.2f}" for name in path_metrics if f"{name}_mean" in last)
    return (
        f"; last evaluation {last[f'{metric}_mean']:.2f} {metric}{f' ({paths})' if paths else ''}, "
        f"best {best[f'{metric}_mean']:.2f} at {best['env_steps'] / 1e6:.1f} M"
    )


def status_metrics(task: Task, records: list[dict]) -> tuple[str, tuple[str, ...]]:
    """(the measure a run's status leads with, the others beside it): the task's selection metric
    (Baoding: round rotations, roto's count beside it) where its records have it, else the headline."""
    from roto.tasks.base import lead_metric

    lead = lead_metric(task, records)
    return lead, tuple(m for m in (task.headline_metric, *task.path_metric_names) if m != lead)


FINISHED = ("done", "stale")
"""The statuses of a cell with a summary: a worker trains neither (it refuses to start beside a
stale one, ``roto.olympiad.staleness.refuse_stale``)."""


def dry_run_report(
    plan: Plan, root: str, results: pathlib.Path, storage: str | None, workers: int = 1, whole: Plan | None = None
) -> str:
    """The cells and their status, and the time left for the env steps left (a started cell counts
    the env steps of its run's last evaluation; ``time_left_estimate``). ``whole``: the plan
    ``--only`` chose ``plan``'s cells from, whose finished cells give the throughput."""
    from roto.jobs.storage import journal_of
    from roto.olympiad.staleness import describe, stale_cells
    from roto.olympiad.time_left import recent_rate
    from roto.olympiad.worker import cell_status
    from roto.rl.evaluation import read_evaluations
    from roto.tasks import get_task

    status = cell_status(plan, root, results, storage)
    stale = stale_cells(plan, results) if "stale" in status.values() else {}
    tasks = {cell.name: get_task(cell.task) for cell in plan.cells}
    budgets = {cell.name: plan.steps_for(cell) for cell in plan.cells}
    uniform = len(set(budgets.values())) == 1
    each = f"{plan.steps} env steps each" if uniform else "env steps per cell as listed"
    chosen = f" of its {len(whole.cells)} (--only)" if whole is not None else ""
    lines = [f"plan {plan.name}: {len(plan.cells)} cells{chosen}, {each}", ""]
    done_steps, started_rates = {}, []
    for name, state in status.items():
        records = [] if state in FINISHED else read_evaluations(pathlib.Path(root) / plan.name / name)
        done_steps[name] = min(int(records[-1]["env_steps"]), budgets[name]) if records else 0
        if rate_now := recent_rate(records):
            started_rates.append(rate_now)
        so_far = headline_so_far(records, *status_metrics(tasks[name], records))
        progress = f" ({done_steps[name] / 1e6:.1f} M env steps{so_far})" if records else ""
        budget = "" if uniform else f" [{budgets[name] / 1e6:g} M]"
        lines.append(f"  {name:<52} {state}{budget}{progress}")
        if name in stale:  # summary's -> plan's
            lines.append(f"    trained otherwise: {describe(stale[name])}")
    left = sum(state not in FINISHED for state in status.values())
    journal = journal_of(pathlib.Path(root) / plan.name, storage)
    if left and journal is not None and not journal.is_file():
        lines += ["", f"no workers' journal at {journal}: a cell running under another --root shows as not started"]
    steps_left = {name: budgets[name] - done_steps[name] for name, state in status.items() if state not in FINISHED}
    kept = f"{len(stale)} stale (not trained again), " if stale else ""
    lines += ["", f"{len(status) - left - len(stale)} done, {kept}{left} left; time left: "]
    lines[-1] += time_left_estimate(whole or plan, results, steps_left, started_rates, workers)
    return "\n".join(lines)


def time_left_estimate(
    plan: Plan, results: pathlib.Path, steps_left: dict[str, int], started_rates: list[float], workers: int
) -> str:
    """How long ``steps_left`` (env steps left per unfinished cell of ``plan``) takes: each cell
    at its task's finished cells' throughput (the plan's summaries in ``results``), a task with
    none at all the finished cells' throughput, or with none finished at the started cells' latest
    throughput; for one worker, and with several, until the busiest one is done ("none" when no
    cell is left)."""
    from roto.olympiad.plan import Cell
    from roto.olympiad.results import read_summaries
    from roto.olympiad.time_left import busiest_worker_load, cell_seconds, rate_sources, task_throughputs, throughput

    if not steps_left:
        return "none, every cell has finished"
    cells = set(plan.cells)
    try:
        summaries = [s for s in read_summaries(results) if Cell.of_summary(s) in cells]
    except FileNotFoundError:
        summaries = []
    rates = task_throughputs(summaries)
    if rates:
        fallback, source = throughput(summaries), "all the finished cells' throughput"
    elif started_rates:
        fallback, source = sum(started_rates) / len(started_rates), "the started cells' last evaluation rounds"
    else:
        return f"unknown: no finished cell's summary in {results} (--results names the folder)"
    task_of = {cell.name: cell.task for cell in plan.cells}
    seconds = cell_seconds(steps_left, task_of, rates, fallback)
    at = rate_sources(rates, (task_of[name] for name in steps_left), fallback, source)
    estimate = f"{sum(seconds.values()) / 3600:.1f} h for one worker at {at}"
    if workers > 1:
        estimate += f"\nwith {workers} workers: {busiest_worker_load(seconds.values(), workers) / 3600:.1f} h"
    return estimate


def cmd_pages(pages: list[str]) -> int:
    """Rewrite each page's generated tables (``roto.olympiad.page_blocks.refresh_blocks``;
    sources relative to the current directory, the repository's root); nothing is written unless
    every page reads, holds generated blocks that all read, and every table can be made."""
    from roto.olympiad.page_blocks import check_blocks, refresh_blocks
    from roto.result_files import write_text_atomic
    from roto.text_files import read_text

    texts = {page: read_text(page, "page") for page in pages}  # every page read and checked first
    for page, text in texts.items():
        check_blocks(text, page)
    fresh = {page: refresh_blocks(text, ".") for page, text in texts.items()}  # then every table made
    changed = [page for page in pages if fresh[page] != texts[page]]
    for page in changed:
        write_text_atomic(page, fresh[page])
    print(json.dumps({"pages": pages, "changed": changed}))
    return 0


def cmd_results(args: argparse.Namespace) -> int:
    """Write the tables and curves (with ``--check FILE``: check one submission, write nothing)."""
    from roto.olympiad.plan import load_plan
    from roto.olympiad.results_page import write_results

    if args.check is not None:
        if args.source or args.out or args.submissions or args.pages:
            raise ValueError("roto results --check FILE checks one submission and writes nothing; give it alone")
        return cmd_check(args.check)
    if args.pages is not None:
        if args.source or args.out or args.submissions:
            raise ValueError("roto results --pages PAGE... refreshes the pages' generated tables; give it alone")
        return cmd_pages(args.pages)
    if args.source is None or args.out is None:
        raise ValueError("roto results needs SOURCE (a plan or a folder of summaries) and --out FOLDER")
    folder = pathlib.Path(args.source)
    if folder.is_dir():
        plan = load_plan(args.plan) if args.plan else None
    else:  # a plan, whose default results folder is read
        try:
            plan = load_plan(args.source)
        except FileNotFoundError as error:
            raise FileNotFoundError(
                f"SOURCE {args.source!r} is neither a folder of cell summaries nor a plan ({error})"
            ) from None
        folder = pathlib.Path(args.root) / plan.name / "results"
    print(json.dumps(write_results(folder, args.out, plan=plan, submissions=args.submissions)))
    return 0

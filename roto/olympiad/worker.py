"""Olympiad workers: cells handed out through an Optuna study, on one machine or many.

Each cell is a trial enqueued in the study ``olympiad-<plan>`` (the journal in ``<root>/<plan>``
or a database, as for sweeps, ``roto.jobs.storage``), its name in the trial's ``cell`` user
attribute. A worker enqueues every cell that has neither a summary nor a live trial, then claims
waiting trials until none is waiting or running. A worker that dies leaves its trial without a
heartbeat; the next worker to look fails it and enqueues a retry, which continues the cell's run
from its latest checkpoint and is claimed before any fresh cell, as is any cell whose run has a
checkpoint, the most trained first (so interrupted cells finish first, and a partial grid is as
complete as it can be). Should a cell be enqueued twice (workers starting at once), the trial
with the higher number sees the other running or complete and ends as a duplicate: no cell
trains twice.
"""

from __future__ import annotations

import pathlib
from collections.abc import Callable, Collection, Sequence
from typing import Any

import optuna
from optuna.exceptions import UpdateFinishedTrialError
from optuna.trial import TrialState

from roto.envs.roto_env import RotoEnv
from roto.jobs.claims import run_claimed, tell_failed
from roto.jobs.flags import HEARTBEAT_S
from roto.jobs.optuna_ids import storage_id
from roto.jobs.storage import RETRY_OF_ATTR, fail_stale_trials, find_study, open_storage, reclaim_now, wait_for_running
from roto.olympiad.cell import code_commit, run_cell, summary_path
from roto.olympiad.plan import Cell, Plan, select_cells
from roto.olympiad.staleness import refuse_stale, retrain_remedy, stale_cells
from roto.rl.evaluation import read_evaluations
from roto.rl.run_dir import checkpoint_path

CELL_ATTR = "cell"
LIVE = (TrialState.RUNNING, TrialState.WAITING)
"""A cell's trial in these states keeps it: nothing else is enqueued for it. A cell whose trial
finished but whose summary is gone (taken away to continue its run to a longer budget) is enqueued
again; its run directory continues where it stopped."""


def study_name(plan: Plan) -> str:
    """The Optuna study that hands out ``plan``'s cells."""
    return f"olympiad-{plan.name}"


def open_olympiad(plan: Plan, root: str, storage_url: str | None) -> tuple[optuna.Study, optuna.storages.BaseStorage]:
    """The plan's study (created when missing)."""
    storage = open_storage(pathlib.Path(root) / plan.name, storage_url)
    study = optuna.create_study(study_name=study_name(plan), storage=storage, direction="maximize", load_if_exists=True)
    return study, storage


def cell_trials(study: optuna.Study, states: tuple[TrialState, ...]) -> dict[str, list[optuna.trial.FrozenTrial]]:
    """{cell name: its trials in ``states``}."""
    found: dict[str, list] = {}
    for trial in study.get_trials(deepcopy=False, states=states):
        if CELL_ATTR in trial.user_attrs:
            found.setdefault(trial.user_attrs[CELL_ATTR], []).append(trial)
    return found


def enqueue_missing(study: optuna.Study, plan: Plan, results: pathlib.Path) -> list[Cell]:
    """Enqueue every cell without a summary and without a live trial; the cells enqueued."""
    live = cell_trials(study, LIVE)
    missing = [c for c in plan.cells if c.name not in live and not summary_path(results, c).is_file()]
    for cell in missing:
        study.enqueue_trial({}, user_attrs={CELL_ATTR: cell.name})
    return missing


def is_duplicate(study: optuna.Study, number: int, cell: str, done: bool) -> bool:
    """Whether ``cell`` is another trial's: it has its summary (``done``), or a lower-numbered trial
    of it runs."""
    running = cell_trials(study, (TrialState.RUNNING,)).get(cell, [])
    return done or any(t.number < number for t in running)


def claim_next(
    study: optuna.Study,
    storage: optuna.storages.BaseStorage,
    trained: Callable[[str], int | None] = lambda cell: None,
    wanted: Collection[str] | None = None,
) -> optuna.Trial | None:
    """Claim a waiting trial: retries and started cells before fresh ones, the most trained first,
    then by number; None when none waits. ``trained(cell name)``: the env steps its run has trained,
    None for a cell not started. A started cell's trial need not be a retry: Optuna's retries of one
    trial run out after ``roto.jobs.storage.MAX_RETRY`` (3), and a cell reclaimed at the end of
    every sitting is then enqueued afresh, at the back of the queue. ``wanted``: claim only the
    trials of these cells (``--only``); None: any.

    As ``optuna.Study.ask`` claims one, but in this order: setting a waiting trial running is
    atomic in every storage, so two workers never claim the same trial.
    """
    waiting = [t for t in study.get_trials(deepcopy=False, states=(TrialState.WAITING,)) if is_wanted(t, wanted)]

    def order(trial: optuna.trial.FrozenTrial) -> tuple[bool, int, int]:
        steps = trained(trial.user_attrs.get(CELL_ATTR, ""))
        return RETRY_OF_ATTR not in trial.system_attrs and steps is None, -(steps or 0), trial.number

    for trial in sorted(waiting, key=order):
        try:
            if storage.set_trial_state_values(storage_id(trial), TrialState.RUNNING):
                return optuna.Trial(study, storage_id(trial))
        except UpdateFinishedTrialError:  # another worker claimed and finished it meanwhile
            continue
    return None


def is_wanted(trial: optuna.trial.FrozenTrial, wanted: Collection[str] | None) -> bool:
    """Whether ``trial`` trains one of the ``wanted`` cells (every trial when None)."""
    return wanted is None or trial.user_attrs.get(CELL_ATTR) in wanted


def trained_steps(run_dir: pathlib.Path) -> int | None:
    """The env steps of the run's last evaluation (0 before the first), None without a checkpoint."""
    if not checkpoint_path(run_dir).is_file():
        return None
    records = read_evaluations(run_dir)
    return int(records[-1]["env_steps"]) if records else 0


def run_olympiad_worker(
    plan: Plan,
    root: str = "runs/olympiad",
    results: str | pathlib.Path | None = None,
    storage_url: str | None = None,
    heartbeat: float = HEARTBEAT_S,
    env_factory: Callable[[Any], Any] = RotoEnv,
    reclaim: bool = False,
    only: Sequence[str] = (),
) -> int:
    """Train cells until none is waiting or running; the number this worker finished.
    ``reclaim``: first fail and retry every running cell (``--reclaim-now``). ``only``: cell name
    patterns (``roto.olympiad.plan.select_cells``): enqueue, claim and wait for only those cells,
    leaving the plan's others to workers without them."""
    results = pathlib.Path(results) if results is not None else pathlib.Path(root) / plan.name / "results"
    chosen = select_cells(plan, only)
    refuse_stale(chosen, results, retrain_remedy(plan, root))  # a summary the plan no longer describes is not done
    study, storage = open_olympiad(plan, root, storage_url)
    enqueue_missing(study, chosen, results)
    wanted = {cell.name for cell in chosen.cells} if only else None
    cells = {cell.name: cell for cell in plan.cells}
    root_dir = pathlib.Path(root) / plan.name
    commit = code_commit()  # the code this worker trains with, read before the checkout can move on
    if reclaim:
        reclaim_now(study, storage)
    finished, told = 0, set()
    while True:
        fail_stale_trials(study, storage, grace=4 * heartbeat)
        trial = claim_next(
            study, storage, lambda name: trained_steps(root_dir / name) if name in cells else None, wanted
        )
        if trial is None:  # while one of its cells runs elsewhere, wait: a dead worker's comes back as a retry
            if wait_for_running(study, heartbeat, told, lambda t: is_wanted(t, wanted)):
                continue
            return finished
        name = trial.user_attrs.get(CELL_ATTR)
        if name not in cells:
            tell_failed(study, trial, f"unknown cell {name!r}: not in plan {plan.name!r}")
            continue
        if is_duplicate(study, trial.number, name, summary_path(results, cells[name]).is_file()):
            tell_failed(study, trial, f"duplicate: another trial has cell {name}")
            continue
        run_dir = root_dir / name

        def work(_: dict, cell: Cell = cells[name], run_dir: pathlib.Path = run_dir) -> float:
            summary = run_cell(plan, cell, run_dir, results, commit, env_factory)
            return summary["final"]["return_mean"]

        finished += run_claimed(study, storage, trial, heartbeat, work)


def cell_status(plan: Plan, root: str, results: pathlib.Path, storage_url: str | None) -> dict[str, str]:
    """{cell name: done, stale (its summary trained otherwise than the plan trains it now,
    ``roto.olympiad.staleness``), running, waiting, failed or not started} without creating anything."""
    status = {c.name: ("done" if summary_path(results, c).is_file() else "not started") for c in plan.cells}
    status.update(dict.fromkeys(stale_cells(plan, results), "stale"))
    study = find_study(pathlib.Path(root) / plan.name, study_name(plan), storage_url)
    if study is None:
        return status
    by_state = (
        ("failed", (TrialState.FAIL,)),
        ("waiting", (TrialState.WAITING,)),
        ("running", (TrialState.RUNNING,)),
    )
    # later labels win: a cell failed once and now running is running; done and stale, its summary's
    for label, states in by_state:
        for name in cell_trials(study, states):
            if name in status and status[name] not in ("done", "stale"):
                status[name] = label
    return status

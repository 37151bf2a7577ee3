"""A sweep worker: claim a trial, train it, record it, until the study has its trials.

Any number of workers, in any number of processes or machines, run this same loop on one study.
Before each trial a worker fails and re-enqueues trials whose worker died (``storage``); it stops
when the finished, running and waiting trials reach the study's count. Trial numbers come from the
storage, so a trial that would exceed the count (two workers asking at once for the last one)
is told failed at once, as surplus, and trains nothing.
"""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

import optuna
from optuna.exceptions import UpdateFinishedTrialError
from optuna.trial import TrialState

from roto.envs.roto_env import RotoEnv
from roto.sweep.space import SearchSpace, load_space
from roto.sweep.storage import REASON_ATTR, Heartbeat, enqueue_retry, fail_stale_trials
from roto.sweep.study import SweepSettings, open_study
from roto.sweep.trial import Diverged, run_trial

ACTIVE = (TrialState.COMPLETE, TrialState.PRUNED, TrialState.RUNNING)
"""Trials that have their outcome or are being trained: when they reach the count, a worker stops."""
CLAIMED = (*ACTIVE, TrialState.WAITING)
"""Trials that count towards the study's trial count (a waiting one is an enqueued retry; failed ones
do not count)."""


def claimed_before(study: optuna.Study, number: int) -> int:
    """Trials numbered below ``number`` that count towards the study's trial count."""
    return sum(t.number < number for t in study.get_trials(deepcopy=False, states=CLAIMED))


def run_worker(settings: SweepSettings, env_factory: Callable[[Any], Any] = RotoEnv) -> int:
    """Run trials until the study has ``settings.trials``; the number of trials this worker finished."""
    space = load_space(settings.space, settings.base_env(), settings.agent_cfg, settings.overrides)  # checked first
    study, storage = open_study(settings)
    finished = 0
    while True:
        fail_stale_trials(study, storage, grace=4 * settings.heartbeat)
        if len(study.get_trials(deepcopy=False, states=ACTIVE)) >= settings.trials:
            return finished
        trial = study.ask()
        if claimed_before(study, trial.number) >= settings.trials:
            trial.set_user_attr(REASON_ATTR, "surplus: the study had its trials")
            study.tell(trial, state=TrialState.FAIL)
            return finished
        finished += _run_one(study, storage, trial, settings, space, env_factory)


def _run_one(
    study: optuna.Study,
    storage: optuna.storages.BaseStorage,
    trial: optuna.Trial,
    settings: SweepSettings,
    space: SearchSpace,
    env_factory: Callable[[Any], Any],
) -> int:
    """Train one claimed trial with a heartbeat and tell its outcome; 1 if it finished, else 0."""
    trial_id = trial._trial_id  # the storage's id: heartbeats and system attributes are written by id
    start = time.perf_counter()
    state, value, reason = TrialState.COMPLETE, None, None
    try:
        with Heartbeat(storage, trial_id, settings.heartbeat):
            value = run_trial(trial, settings, space, storage.get_trial(trial_id).system_attrs, env_factory)
    except (optuna.TrialPruned, Diverged) as error:
        state, reason = TrialState.PRUNED, str(error)
    except BaseException as error:  # Ctrl-C or a crash: fail it and enqueue a retry that resumes its run
        _fail_and_retry(study, storage, trial, f"{type(error).__name__}: {error}")
        raise
    try:
        if reason:
            trial.set_user_attr(REASON_ATTR, reason)
        study.tell(trial, value, state=state)
    except UpdateFinishedTrialError:  # declared dead while it ran (a stalled heartbeat); its retry counts
        return 0
    shown = f"{value:.3f}" if value is not None else reason
    print(f"trial {trial.number}: {state.name.lower()}, {shown} ({time.perf_counter() - start:.0f} s)", flush=True)
    return 1


def _fail_and_retry(
    study: optuna.Study, storage: optuna.storages.BaseStorage, trial: optuna.Trial, reason: str
) -> None:
    """Tell ``trial`` failed with ``reason`` and enqueue a retry (unless another worker failed it first)."""
    try:
        trial.set_user_attr(REASON_ATTR, reason)
        study.tell(trial, state=TrialState.FAIL)
    except UpdateFinishedTrialError:
        return
    enqueue_retry(study, storage.get_trial(trial._trial_id))


def launch_workers(count: int, argv: Sequence[str]) -> int:
    """Run ``count`` ``roto sweep`` worker processes with ``argv`` here; the worst exit code.

    Ctrl-C reaches every worker (one process group); each fails and re-enqueues its running trial.
    """
    command = [sys.executable, "-m", "roto.cli", "sweep", *argv, "--workers", "1"]
    processes = [subprocess.Popen(command) for _ in range(count)]
    try:
        return max(p.wait() for p in processes)
    except KeyboardInterrupt:
        return max(p.wait() for p in processes)

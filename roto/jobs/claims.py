"""Running a claimed trial: heartbeat while it works, then tell the storage how it ended.

Shared by ``roto sweep`` (a trial is a set of parameters) and ``roto olympiad`` (a trial is a
cell of the plan). A ``optuna.TrialPruned`` from the work ends the trial pruned with its message
as the reason; a trial another worker has meanwhile declared dead (its report or its outcome
refused) is left to its retry, which continues the run or finds its result; any other exception,
Ctrl-C and SIGTERM included, fails it and enqueues a retry, then goes on up. ``launch_workers``
starts worker processes of a ``roto`` subcommand here.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from collections.abc import Callable, Sequence

import optuna
from optuna.exceptions import UpdateFinishedTrialError
from optuna.trial import TrialState

from roto.jobs.optuna_ids import storage_id
from roto.jobs.storage import REASON_ATTR, Heartbeat, enqueue_retry
from roto.rl.stop_requests import signal_handlers


def run_claimed(
    study: optuna.Study,
    storage: optuna.storages.BaseStorage,
    trial: optuna.Trial,
    interval: float,
    work: Callable[[dict], float],
) -> bool:
    """``work(system_attrs)`` with a heartbeat every ``interval`` s, then tell its outcome.

    Returns True when the outcome was told, False when another worker had declared the trial dead
    meanwhile (its retry then counts instead).
    """
    trial_id = storage_id(trial)  # the storage's id: heartbeats and system attributes are written by id
    start = time.perf_counter()
    state, value, reason = TrialState.COMPLETE, None, None
    try:
        with Heartbeat(storage, trial_id, interval):
            value = work(storage.get_trial(trial_id).system_attrs)
    except optuna.TrialPruned as error:
        state, reason = TrialState.PRUNED, str(error)
    except UpdateFinishedTrialError:  # declared dead by another worker (a long silence): its retry takes over
        print(f"trial {trial.number}: declared dead by another worker; its retry continues the run", flush=True)
        return False
    except BaseException as error:  # Ctrl-C or a crash: fail it and enqueue a retry that resumes its run
        fail_and_retry(study, storage, trial, f"{type(error).__name__}: {error}")
        raise
    try:
        if reason:
            trial.set_user_attr(REASON_ATTR, reason)
        told = study.tell(trial, value, state=state, skip_if_finished=True)
    except UpdateFinishedTrialError:
        told = storage.get_trial(trial_id)
    if told.state != state:  # failed by another worker while the work ran (--reclaim-now there, or a silence)
        print(
            f"trial {trial.number}: its work ended here, but another worker had already ended the trial "
            f"({told.state.name.lower()}) and enqueued its retry, which counts instead",
            flush=True,
        )
        return False
    shown = f"{value:.3f}" if value is not None else reason
    print(f"trial {trial.number}: {state.name.lower()}, {shown} ({time.perf_counter() - start:.0f} s)", flush=True)
    return True


def tell_failed(study: optuna.Study, trial: optuna.Trial, reason: str) -> None:
    """End a claimed trial that will not run (surplus, duplicate) as failed, with the reason."""
    trial.set_user_attr(REASON_ATTR, reason)
    study.tell(trial, state=TrialState.FAIL)


def fail_and_retry(study: optuna.Study, storage: optuna.storages.BaseStorage, trial: optuna.Trial, reason: str) -> None:
    """Tell ``trial`` failed with ``reason`` and enqueue a retry (unless another worker failed it first)."""
    try:
        tell_failed(study, trial, reason)
    except UpdateFinishedTrialError:
        return
    enqueue_retry(study, storage.get_trial(storage_id(trial)))


def launch_workers(command: str, count: int, argv: Sequence[str]) -> int:
    """Run ``count`` ``roto <command> <argv> --workers 1`` processes here; 0 when every worker
    succeeded, else the first failing worker's exit code (1 for a worker killed by a signal), each
    failure named on stderr.

    Ctrl-C reaches every worker (one process group); a SIGTERM sent to this process alone (``kill``, a
    scheduler) is passed on to each. Either way each worker finishes its update, checkpoints, fails
    and re-enqueues its running trial (``roto.rl.stop_requests``), and this waits for them.
    """
    line = [sys.executable, "-m", "roto.cli", command, *argv, "--workers", "1"]
    processes = [subprocess.Popen(line) for _ in range(count)]
    return worst_exit(wait_passing_on_sigterm(processes), [p.pid for p in processes])


def wait_passing_on_sigterm(processes: Sequence[subprocess.Popen]) -> list[int]:
    """Every process's exit code, once all have ended; a SIGTERM this process gets meanwhile is sent
    on to those still running (in the main thread; elsewhere SIGTERM keeps its handler)."""

    def pass_on(signum: int, frame: object) -> None:
        for p in processes:
            if p.poll() is None:
                p.send_signal(signum)

    with signal_handlers({signal.SIGTERM: pass_on}):
        try:
            return [p.wait() for p in processes]
        except KeyboardInterrupt:  # Ctrl-C reached the workers too: wait for their clean stops
            return [p.wait() for p in processes]


def worst_exit(codes: Sequence[int], pids: Sequence[int]) -> int:
    """The command's exit code from its workers' (``Popen.returncode``: negative for a signal),
    naming every failed worker on stderr."""
    failed = [(k, pid, code) for k, (pid, code) in enumerate(zip(pids, codes, strict=True)) if code != 0]
    for k, pid, code in failed:
        how = f"was killed by {signal.Signals(-code).name}" if code < 0 else f"exited with {code}"
        print(f"roto: worker {k + 1} of {len(codes)} (pid {pid}) {how}", file=sys.stderr)
    if not failed:
        return 0
    code = failed[0][2]
    return code if code > 0 else 1

"""Faults a sweep must survive: a torn journal line, a database that goes away, workers that died."""

import multiprocessing
import time
from dataclasses import replace

import optuna
import pytest
import sqlalchemy.exc
import torch
from optuna.exceptions import StorageInternalError
from optuna.trial import TrialState

from roto.jobs.journal import TAIL_CHUNK, drop_torn_tail
from roto.jobs.retrying_storage import DatabaseUnreachable, RetryingStorage
from roto.jobs.storage import HEARTBEAT_ATTR, JOURNAL_NAME, REASON_ATTR, open_storage
from roto.rl.evaluation import read_evaluations
from roto.sweep.study import open_study
from roto.sweep.trial import run_dir_of
from roto.sweep.worker import run_worker
from tests.rl.toy_env import ToyEnv
from tests.sweep.postgres_server import running_server
from tests.sweep.toy_sweep import toy_settings, toy_worker

FINISHED = (TrialState.COMPLETE, TrialState.PRUNED)


@pytest.mark.parametrize(
    ("content", "kept"),
    [
        (b"", b""),
        (b'{"a":1}\n', b'{"a":1}\n'),
        (b'{"a":1}\n{"b":', b'{"a":1}\n'),
        (b'{"b":', b""),
        (b'{"a":1}\n' + b"x" * (3 * TAIL_CHUNK), b'{"a":1}\n'),  # a torn line longer than one read
    ],
)
def test_drop_torn_tail_cuts_back_to_the_last_newline(tmp_path, content, kept):
    path = tmp_path / "journal.log"
    path.write_bytes(content)
    assert drop_torn_tail(path) == len(content) - len(kept)
    assert path.read_bytes() == kept


def test_a_torn_last_journal_line_is_dropped_with_a_warning_and_the_study_goes_on(tmp_path, capfd):
    torch.set_num_threads(1)
    settings = toy_settings(tmp_path, trials=2, updates=2)
    assert run_worker(settings, env_factory=ToyEnv) == 2
    journal = settings.study_dir / JOURNAL_NAME
    whole = journal.read_bytes()
    journal.write_bytes(whole + b'{"op_code":5,"worker_id":"dead","trial_id":1,"sta')  # a writer died mid-line

    extended = toy_settings(tmp_path, trials=3, updates=2)
    assert run_worker(extended, env_factory=ToyEnv) == 1
    assert "dropped a torn last line (49 bytes)" in capfd.readouterr().err
    assert journal.read_bytes().startswith(whole)
    study = optuna.load_study(study_name=settings.study, storage=open_storage(settings.study_dir))
    assert len(study.get_trials(states=FINISHED)) == 3


def lost_connection() -> StorageInternalError:
    """What Optuna's database storage raises when the server went away mid-call."""
    try:
        raise sqlalchemy.exc.OperationalError("SELECT 1", {}, Exception("server closed the connection unexpectedly"))
    except sqlalchemy.exc.OperationalError as cause:
        try:
            raise StorageInternalError(
                "An exception is raised during the commit. invalid data in the commit"
            ) from cause
        except StorageInternalError as error:
            return error


class FlakyStorage:
    """Raises ``failures`` lost connections on ``get_trial``, then answers."""

    def __init__(self, failures: int, error: Exception | None = None) -> None:
        self.failures, self.calls, self.error = failures, 0, error

    def get_trial(self, trial_id):
        self.calls += 1
        if self.calls <= self.failures:
            raise self.error or lost_connection()
        return f"trial {trial_id}"


def test_a_lost_connection_is_retried_with_growing_pauses_until_it_answers(capsys):
    pauses = []
    storage = RetryingStorage(FlakyStorage(failures=4), "postgresql://roto:***@db/roto", sleep=pauses.append)
    assert storage.get_trial(7) == "trial 7"
    assert pauses == [0.25, 0.5, 1.0, 2.0]
    assert capsys.readouterr().err.count("unreachable (server closed the connection unexpectedly)") == 1


class Sessions:
    """A database storage's per-thread sessions: counts how often the thread's session is dropped."""

    def __init__(self) -> None:
        self.removed = 0

    def remove(self) -> None:
        self.removed += 1


def broken_session() -> StorageInternalError:
    """What Optuna's database storage raises when a call reuses a session whose transaction a lost
    connection broke (seen when the database restarted under a loaded two-worker sweep)."""
    try:
        raise sqlalchemy.exc.PendingRollbackError("Can't reconnect until invalid transaction is rolled back.")
    except sqlalchemy.exc.PendingRollbackError as cause:
        try:
            raise StorageInternalError("An exception is raised during the commit.") from cause
        except StorageInternalError as error:
            return error


def test_a_session_broken_by_a_lost_connection_is_dropped_and_the_call_retried(capsys):
    inner = FlakyStorage(failures=2, error=broken_session())
    inner.scoped_session = Sessions()
    storage = RetryingStorage(inner, "postgresql://roto:***@db/roto", sleep=lambda s: None)
    assert storage.get_trial(3) == "trial 3" and inner.calls == 3
    assert inner.scoped_session.removed == 2  # before each retry: a fresh session, not the broken one
    assert "unreachable (Can't reconnect until invalid transaction is rolled back.)" in capsys.readouterr().err


def test_other_errors_are_raised_at_once():
    inner = FlakyStorage(failures=1, error=ValueError("bad value"))
    storage = RetryingStorage(
        inner, "db", sleep=lambda s: pytest.fail("retried an error that is not a lost connection")
    )
    with pytest.raises(ValueError, match="bad value"):
        storage.get_trial(1)
    assert inner.calls == 1


def test_a_database_down_for_the_whole_window_is_named_with_the_drivers_reason():
    storage = RetryingStorage(FlakyStorage(failures=10**6), "postgresql://roto:***@db/roto", window_s=0.0)
    with pytest.raises(DatabaseUnreachable) as raised:
        storage.get_trial(1)
    message = str(raised.value)
    assert "'postgresql://roto:***@db/roto' was unreachable for 0 s: server closed the connection" in message
    assert "invalid data" not in message


def claim_as_dead_workers(settings, count: int) -> None:
    """Leave ``count`` running trials with fresh heartbeats, as workers that crashed just now would."""
    study, storage = open_study(settings)
    for _ in range(count):
        trial = study.ask()
        storage.set_trial_system_attr(trial._trial_id, HEARTBEAT_ATTR, time.time())


def test_a_rerun_right_after_workers_died_waits_for_their_trials_and_retries_them(tmp_path, capsys):
    torch.set_num_threads(1)
    settings = toy_settings(tmp_path, trials=2, updates=2, heartbeat=0.25)
    claim_as_dead_workers(settings, 2)
    assert run_worker(settings, env_factory=ToyEnv) == 2  # not 0: it waited out the grace period
    assert "waiting for running trials [0, 1]" in capsys.readouterr().out
    study = optuna.load_study(study_name=settings.study, storage=open_storage(settings.study_dir))
    assert [t.state for t in study.trials[:2]] == [TrialState.FAIL, TrialState.FAIL]
    assert all("no heartbeat" in t.user_attrs[REASON_ATTR] for t in study.trials[:2])
    assert len(study.get_trials(states=FINISHED)) == 2


def test_reclaim_now_retries_running_trials_without_waiting(tmp_path, capsys):
    torch.set_num_threads(1)
    settings = toy_settings(tmp_path, trials=2, updates=2, heartbeat=600.0)  # the grace would be 40 minutes
    claim_as_dead_workers(settings, 2)
    assert run_worker(settings, env_factory=ToyEnv, reclaim=True) == 2
    out = capsys.readouterr().out
    assert "reclaimed running trials [0, 1]" in out and "waiting for" not in out
    study = optuna.load_study(study_name=settings.study, storage=open_storage(settings.study_dir))
    assert all(t.user_attrs[REASON_ATTR] == "reclaimed at once (--reclaim-now)" for t in study.trials[:2])
    assert len(study.get_trials(states=FINISHED)) == 2


def test_a_database_restart_during_a_two_worker_sweep_costs_no_worker_and_no_trial(tmp_path, postgres_binaries):
    with running_server(postgres_binaries) as server:
        settings = toy_settings(tmp_path, trials=6, updates=30, study="toy_restart", storage=server.url, heartbeat=2.0)
        open_study(settings)
        context = multiprocessing.get_context("spawn")
        workers = [context.Process(target=toy_worker, args=(settings,)) for _ in range(2)]
        for worker in workers:
            worker.start()
        deadline = time.time() + 120
        while not read_evaluations(run_dir_of(settings, 1)):  # both workers are mid-trial
            assert time.time() < deadline and all(w.is_alive() for w in workers)
            time.sleep(0.2)
        server.restart(2.0)
        for worker in workers:
            worker.join(timeout=300)
        assert [w.exitcode for w in workers] == [0, 0]
        run_worker(settings, env_factory=ToyEnv)  # the rerun finishes whatever a lost trial left
        study = optuna.load_study(study_name=settings.study, storage=open_storage(settings.study_dir, server.url))
        finished = study.get_trials(states=FINISHED)
        assert len(finished) == 6 and not study.get_trials(states=(TrialState.RUNNING, TrialState.WAITING))
        for trial in finished:
            assert trial.value is not None and read_evaluations(run_dir_of(settings, trial.number))


def test_a_database_gone_for_good_is_a_one_line_runtime_failure_of_the_cli():
    from roto.cli_errors import error_exit

    assert error_exit(DatabaseUnreachable("the database 'db' was unreachable for 60 s")) == (1, "failed")


def test_a_live_trial_declared_dead_is_left_to_its_retry_which_continues_its_run(tmp_path, capsys):
    from roto.jobs.storage import reclaim_now

    torch.set_num_threads(1)
    settings = toy_settings(tmp_path, trials=1, updates=8, heartbeat=30.0)
    study, storage = open_study(settings)

    class DeclaredDeadMidTrial(ToyEnv):
        steps = 0

        def step(self, action):
            DeclaredDeadMidTrial.steps += 1
            if DeclaredDeadMidTrial.steps == 40:  # as another worker would after a long silence
                reclaim_now(study, storage)
            return super().step(action)

    assert run_worker(settings, env_factory=DeclaredDeadMidTrial) == 1  # the retry's; no crash on the refused report
    assert "trial 0: declared dead by another worker; its retry continues the run" in capsys.readouterr().out
    study = optuna.load_study(study_name=settings.study, storage=open_storage(settings.study_dir))
    first, retry = study.trials
    assert first.state == TrialState.FAIL and retry.state in FINISHED and retry.system_attrs["failed_trial"] == 0
    steps = [r["env_steps"] for r in read_evaluations(run_dir_of(settings, 0))]
    assert steps == sorted(set(steps)) and steps[-1] == settings.steps  # one run, continued to its end


def test_a_study_in_a_journal_file_carried_to_an_empty_machine_keeps_its_trials_and_retries_the_rest(tmp_path, capsys):
    from roto.sweep.report import show

    torch.set_num_threads(1)
    journal = tmp_path / "results" / "toy.log"  # committed with the results; run directories are not
    first = replace(toy_settings(tmp_path, trials=1, updates=2, storage=str(journal)), root=str(tmp_path / "machine_a"))
    assert run_worker(first, env_factory=ToyEnv) == 1
    claim_as_dead_workers(first, 1)  # a trial still training when the first machine went away
    assert journal.is_file() and not (first.study_dir / JOURNAL_NAME).exists()

    second = replace(first, trials=2, root=str(tmp_path / "machine_b"))
    assert run_worker(second, env_factory=ToyEnv, reclaim=True) == 1
    assert "reclaimed running trials [1]" in capsys.readouterr().out
    study = optuna.load_study(study_name=first.study, storage=open_storage(tmp_path, str(journal)))
    assert [t.state for t in study.trials] == [TrialState.COMPLETE, TrialState.FAIL, TrialState.COMPLETE]
    assert read_evaluations(run_dir_of(second, 1))  # the retry trained from scratch on the new machine
    assert not read_evaluations(run_dir_of(second, 0))  # the finished trial is not trained again
    assert show(first.study, str(tmp_path / "elsewhere"), str(journal)).count("| complete |") == 2


@pytest.mark.parametrize("storage", ["runs/toy", "journal.txt", "postgres"])
def test_a_storage_that_is_neither_a_url_nor_a_journal_file_is_refused_by_name(tmp_path, storage):
    with pytest.raises(ValueError, match=rf"storage '{storage}' is neither a database URL .* nor a journal file"):
        open_storage(tmp_path, storage)
    assert not (tmp_path / storage).exists()

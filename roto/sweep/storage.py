"""Where a study lives, and how a dead worker's trial is found and retried.

Storage: Optuna's journal file in the study's folder by default (processes on one machine, or
machines sharing a filesystem); a journal file elsewhere, named by its path (``*.log``: kept with
the results and committed, it carries a study's finished trials to a machine that starts empty);
or any database URL Optuna accepts (``postgresql://...``: workers on many machines join one study
by running the same command).

Liveness: a worker's running trial carries a heartbeat (a system attribute with the time, written
every ``interval`` seconds by a thread). Before each new trial, a worker marks every running
trial whose heartbeat is older than ``grace`` seconds as failed and enqueues a retry of it with the
same parameters (Optuna's ``RetryHeartbeatStaleTrialCallback``); the retry resumes the dead trial's run
directory from its latest checkpoint. This works the same on the journal and on a database
(Optuna's own heartbeat exists only for databases). Machines' clocks must agree to well within
``grace``.
"""

from __future__ import annotations

import importlib.util
import math
import pathlib
import sys
import threading
import time
import urllib.parse
import warnings

import optuna
import sqlalchemy.exc
from optuna.exceptions import UpdateFinishedTrialError
from optuna.storages import RetryHeartbeatStaleTrialCallback
from optuna.storages.journal import JournalStorage
from optuna.trial import TrialState

from roto.sweep.journal import JournalFile
from roto.sweep.retrying_storage import RetryingStorage, first_line

JOURNAL_NAME = "journal.log"
HEARTBEAT_ATTR = "roto:heartbeat"
REASON_ATTR = "reason"
RETRY_OF_ATTR = "failed_trial"
"""System attribute of a retry (written by Optuna's retry callback): the number of the first try."""
MAX_RETRY = 3
"""Retries of one trial after its worker died (then it stays failed)."""

with warnings.catch_warnings():  # Optuna marks the callback experimental; roto relies only on what it records
    warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
    enqueue_retry = RetryHeartbeatStaleTrialCallback(max_retry=MAX_RETRY)
"""``enqueue_retry(study, failed_trial)``: a waiting copy of the trial, its system attribute
``RETRY_OF_ATTR`` naming the first try."""


def redact_url(url: str) -> str:
    """``url`` with its password replaced by ``***`` (for messages and logs)."""
    parts = urllib.parse.urlsplit(url)
    if parts.password is None:
        return url
    netloc = parts.netloc.replace(f":{parts.password}@", ":***@", 1)
    return urllib.parse.urlunsplit(parts._replace(netloc=netloc))


CONNECT_TIMEOUT_S = 10
"""Seconds a database connection may take before the storage gives up (a host that accepts the
connection and never answers would otherwise hang the command)."""


def database_url(url: str) -> str:
    """``url`` with a driver SQLAlchemy can load: plain ``postgresql://`` means psycopg 3 to
    SQLAlchemy 2.1, so it becomes ``postgresql+psycopg2://`` where only psycopg2 (roto's
    ``postgres`` extra) is installed."""
    scheme, sep, rest = url.partition("://")
    only_psycopg2 = importlib.util.find_spec("psycopg") is None and importlib.util.find_spec("psycopg2") is not None
    return f"postgresql+psycopg2://{rest}" if scheme == "postgresql" and sep and only_psycopg2 else url


def journal_path(url: str) -> pathlib.Path | None:
    """The journal file ``url`` names (a path ending in ``.log``), or None for a database URL.

    Raises:
        ValueError naming ``url`` when it is neither ``scheme://...`` nor a ``*.log`` path.
    """
    if "://" in url:
        return None
    if not url.endswith(".log"):
        raise ValueError(
            f"storage {url!r} is neither a database URL (e.g. postgresql://user@host/db, sqlite:///file.db) "
            f"nor a journal file's path (ending in .log)"
        )
    return pathlib.Path(url)


def journal_of(study_dir: pathlib.Path, url: str | None) -> pathlib.Path | None:
    """The journal file a study with folder ``study_dir`` and storage ``url`` lives in (the folder's
    own without ``url``), or None when ``url`` is a database."""
    return journal_path(url) if url else study_dir / JOURNAL_NAME


def open_storage(study_dir: pathlib.Path, url: str | None = None) -> optuna.storages.BaseStorage:
    """The journal file in ``study_dir`` (created), the journal file ``url`` names (``*.log``,
    created), or the database at ``url``.

    A database storage retries calls across a lost connection (``RetryingStorage``); the journal
    drops a torn last line before writing (``JournalFile``).

    Raises:
        ValueError naming the URL (password hidden) when the database cannot be reached in
        ``CONNECT_TIMEOUT_S`` or refuses the connection, or when ``url`` is neither a URL nor a
        ``*.log`` path.
    """
    journal = journal_of(study_dir, url)
    if journal is not None:
        journal.parent.mkdir(parents=True, exist_ok=True)
        return JournalStorage(JournalFile(str(journal)))
    driver_url = database_url(url)
    engine = {"pool_pre_ping": True}  # a connection the server dropped is replaced, not used
    if driver_url.startswith("postgresql"):
        engine["connect_args"] = {"connect_timeout": CONNECT_TIMEOUT_S}
    try:
        database = optuna.storages.RDBStorage(driver_url, engine_kwargs=engine)
    except sqlalchemy.exc.SQLAlchemyError as error:
        raise ValueError(f"cannot open the storage {redact_url(url)!r}: {first_line(error)}") from None
    return RetryingStorage(database, redact_url(url))


def find_study(folder: pathlib.Path, name: str, url: str | None = None) -> optuna.Study | None:
    """Study ``name`` in ``folder``'s journal (or the database at ``url``) if it exists; creates nothing."""
    journal = journal_of(folder, url)
    if journal is not None and not journal.is_file():
        return None
    storage = open_storage(folder, url)
    names = [s.study_name for s in optuna.get_all_study_summaries(storage, include_best_trial=False)]
    return optuna.load_study(study_name=name, storage=storage) if name in names else None


class Heartbeat:
    """A thread writing the time into a running trial's system attributes every ``interval`` s."""

    def __init__(self, storage: optuna.storages.BaseStorage, trial_id: int, interval: float) -> None:
        self.storage, self.trial_id, self.interval = storage, trial_id, interval
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def __enter__(self) -> Heartbeat:
        self.storage.set_trial_system_attr(self.trial_id, HEARTBEAT_ATTR, time.time())
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()

    def _run(self) -> None:
        while not self._stop.wait(self.interval):
            try:
                self.storage.set_trial_system_attr(self.trial_id, HEARTBEAT_ATTR, time.time())
            except UpdateFinishedTrialError:  # another worker declared this trial dead
                return
            except Exception as error:  # a storage hiccup: keep beating, the next write may get through
                print(f"heartbeat of trial id {self.trial_id} not written: {error}", file=sys.stderr, flush=True)


def fail_stale_trials(
    study: optuna.Study, storage: optuna.storages.BaseStorage, grace: float, why: str | None = None
) -> list[int]:
    """Mark running trials without a heartbeat for ``grace`` s as failed and enqueue their retries.

    ``why``: the reason stored on each (default: how long it was silent). Returns the numbers of
    the trials this call failed (another worker may fail the same trial at the same time; the
    storage lets exactly one of them do it).
    """
    failed = []
    now = time.time()
    for trial in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        beat = trial.system_attrs.get(HEARTBEAT_ATTR, trial.datetime_start.timestamp())
        if now - beat <= grace:
            continue
        try:
            storage.set_trial_user_attr(trial._trial_id, REASON_ATTR, why or f"no heartbeat for {now - beat:.0f} s")
            if not storage.set_trial_state_values(trial._trial_id, TrialState.FAIL):
                continue
        except UpdateFinishedTrialError:
            continue
        enqueue_retry(study, storage.get_trial(trial._trial_id))
        failed.append(trial.number)
    return failed


def reclaim_now(study: optuna.Study, storage: optuna.storages.BaseStorage) -> list[int]:
    """Fail every running trial at once and enqueue its retry (``--reclaim-now``: the caller knows
    their workers are dead); the numbers of the trials failed."""
    failed = fail_stale_trials(study, storage, grace=-math.inf, why="reclaimed at once (--reclaim-now)")
    if failed:
        print(f"roto: reclaimed running trials {failed}: each is retried from its latest checkpoint", flush=True)
    return failed


def wait_for_running(study: optuna.Study, heartbeat: float, told: set[tuple[int, ...]]) -> bool:
    """Whether trials still run; if so, wait one heartbeat (saying why, once per set of trials).

    A worker with nothing left to claim waits here rather than stopping: a running trial either
    finishes, or its worker has died and the trial is retried once its heartbeat is ``4 *
    heartbeat`` s old, by whichever worker is still looking. ``told``: the sets already announced.
    """
    running = tuple(t.number for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)))
    if not running:
        return False
    if running not in told:
        told.add(running)
        print(
            f"roto: nothing left to claim; waiting for running trials {list(running)}. A trial whose worker died "
            f"is retried here after {4 * heartbeat:.0f} s without a heartbeat (--reclaim-now retries every "
            "running trial at once, when you know no other worker is alive)",
            flush=True,
        )
    time.sleep(heartbeat)
    return True

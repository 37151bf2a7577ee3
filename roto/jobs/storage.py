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

import contextlib
import importlib.util
import math
import os
import pathlib
import re
import sys
import threading
import time
import urllib.parse
import warnings
from collections.abc import Callable, Iterator

import optuna
import sqlalchemy.exc
from optuna.exceptions import StorageInternalError, UpdateFinishedTrialError
from optuna.storages import RetryHeartbeatStaleTrialCallback
from optuna.storages.journal import JournalStorage
from optuna.trial import TrialState

from roto.jobs.journal import JournalFile
from roto.jobs.optuna_ids import storage_id
from roto.jobs.retrying_storage import RetryingStorage, first_line, permission_denied, permission_error

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


SECRET_PARAMETER = re.compile(r"(?:^|[?&;\s])([^?&;=\s]*)=")
"""A ``key=`` of a URL's query string (or of a libpq ``key=value`` string); a key naming a
password (``password``, ``sslpassword``, any case, percent-encoded or not) starts a secret."""
SCHEME = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*://")
STORAGE_ENV = "ROTO_STORAGE_URL"
"""The environment variable that carries ``--storage`` to the workers a command starts (never their
argv, which any local user can read in /proc/PID/cmdline)."""
ENV_PREFIX = "env:"
"""``--storage env:NAME``: the storage is the value of the environment variable ``NAME``."""


def _after_scheme(url: str) -> int:
    """Where the text after ``scheme://`` begins (0 when ``url`` does not begin with one)."""
    found = SCHEME.match(url)
    return found.end() if found else 0


def password_span(url: str) -> tuple[int, int] | None:
    """Where the password of ``user:password@host`` lies in ``url``: from the first ``:`` after the
    scheme to the last ``@`` (a password may hold ``@ : / # ?``); None without one. Without an
    ``@``, a ``:`` followed by no port (``user:password``, the host left out) starts one that runs
    to the end."""
    start, at = _after_scheme(url), url.rfind("@")
    if at >= start:
        colon = url.find(":", start, at)
        return (colon + 1, at) if colon >= 0 else None
    authority = re.match(r"[^/?#]*", url[start:]).group()
    colon = authority.find(":")
    port = authority[colon + 1 :]
    if colon < 0 or authority.startswith("[") or not port or port.isdigit():
        return None
    return start + colon + 1, len(url)


def secret_parameter(url: str) -> tuple[int, int] | None:
    """(where its key begins, where its value begins) of the first ``password=`` parameter of
    ``url``; None without one."""
    for match in SECRET_PARAMETER.finditer(url, _after_scheme(url)):
        if "password" in urllib.parse.unquote_plus(match.group(1)).lower():
            return match.start(1), match.end()
    return None


def secret_regions(url: str) -> tuple[tuple[int, int] | None, int | None]:
    """(the userinfo password's ``password_span``, where a ``password=`` parameter's value begins)
    in ``url``, either None when absent. A span that begins inside the parameter's value is part of
    it: the span is then None."""
    span, parameter = password_span(url), secret_parameter(url)
    if parameter is not None and span is not None and parameter[0] < span[0]:
        span = None
    return span, None if parameter is None else parameter[1]


def redact_url(url: str) -> str:
    """``url`` with its passwords replaced by ``***`` (for messages and logs).

    Found by hand, not by ``urllib`` (which ends a password at ``/``, ``#`` or ``?``): the
    userinfo's password (``password_span``) and everything after a ``password=`` parameter. A
    malformed URL is hidden the same way; at worst more than the password is hidden, never less.
    """
    span, value = secret_regions(url)
    if span is None:
        return url if value is None else f"{url[:value]}***"
    if value is not None and value <= span[1]:  # "password=" inside the userinfo: it may be either
        return f"{url[: span[0]]}***"
    end = len(url) if value is None else value
    return f"{url[: span[0]]}***{url[span[1] : end]}" + ("" if value is None else "***")


def url_secrets(url: str) -> list[str]:
    """The passwords in ``url`` as given and percent-decoded, longest first (to scrub them from a
    driver's messages)."""
    span, value = secret_regions(url)
    found = [url[span[0] : span[1]]] if span else []
    if value is not None:
        found.append(re.split(r"[&;\s]", url[value:])[0])
    found += [urllib.parse.unquote_plus(text) for text in found] + [urllib.parse.unquote(text) for text in found]
    return sorted({text for text in found if text}, key=len, reverse=True)


def scrub(text: str, url: str) -> str:
    """``text`` with each password of ``url`` replaced by ``***``."""
    for secret in url_secrets(url):
        text = text.replace(secret, "***")
    return text


def resolve_storage(value: str | None) -> str | None:
    """``--storage``'s value: ``env:NAME`` becomes the value of environment variable ``NAME``
    (how the workers a command starts get it, ``storage_in_environment``); anything else as given.

    Raises:
        ValueError when the variable is not set.
    """
    if value is None or not value.startswith(ENV_PREFIX):
        return value
    name = value[len(ENV_PREFIX) :]
    url = os.environ.get(name)
    if not url:
        raise ValueError(f"--storage {value}: the environment variable {name!r} is not set (or is empty)")
    return url


@contextlib.contextmanager
def storage_in_environment(url: str | None) -> Iterator[list[str]]:
    """While inside, ``url`` is in this process's environment as ``STORAGE_ENV``, so worker processes
    started here inherit it; yields the worker's ``--storage`` arguments (none without ``url``)."""
    if url is None:
        yield []
        return
    before = os.environ.get(STORAGE_ENV)
    os.environ[STORAGE_ENV] = url
    try:
        yield ["--storage", ENV_PREFIX + STORAGE_ENV]
    finally:
        if before is None:
            os.environ.pop(STORAGE_ENV, None)
        else:
            os.environ[STORAGE_ENV] = before


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
            f"storage {redact_url(url)!r} is neither a database URL (e.g. postgresql://user@host/db, "
            "sqlite:///file.db) nor a journal file's path (ending in .log)"
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
        ``*.log`` path; ``DatabasePermissionDenied`` when the role may not use Optuna's tables.
    """
    journal = journal_of(study_dir, url)
    if journal is not None:
        journal.parent.mkdir(parents=True, exist_ok=True)
        return JournalStorage(JournalFile(str(journal)))
    driver_url = database_url(url)
    check_url_parses(url, driver_url)
    engine = {"pool_pre_ping": True}  # a connection the server dropped is replaced, not used
    if driver_url.startswith("postgresql"):
        engine["connect_args"] = {"connect_timeout": CONNECT_TIMEOUT_S}
    template = driver_url.replace("{", "{{").replace("}", "}}")  # Optuna fills {SCHEMA_VERSION} with str.format
    try:
        database = optuna.storages.RDBStorage(template, engine_kwargs=engine)
    except (sqlalchemy.exc.SQLAlchemyError, StorageInternalError) as error:
        denied = permission_error(error)
        if denied is not None:
            raise permission_denied(redact_url(url), denied) from None
        driver = (error.__cause__ or error) if isinstance(error, StorageInternalError) else error
        raise ValueError(f"cannot open the storage {redact_url(url)!r}: {scrub(first_line(driver), url)}") from None
    return RetryingStorage(database, redact_url(url))


def check_url_parses(url: str, driver_url: str) -> None:
    """Refuse a database URL SQLAlchemy cannot parse, or whose password it reads otherwise than
    ``redact_url`` hides it (an ``@`` in it ends SQLAlchemy's password: the rest would reach the
    server as the host, and its messages). ``driver_url``: ``url`` with the driver named.

    Raises:
        ValueError naming the URL with its password hidden.
    """
    try:
        parsed = sqlalchemy.engine.make_url(driver_url)
    except (sqlalchemy.exc.ArgumentError, ValueError, TypeError):  # e.g. a port that is not a number
        raise ValueError(
            f"the storage {redact_url(url)!r} is not a database URL SQLAlchemy can read "
            "(scheme://user:password@host:port/database; percent-encode @ : / in the user or password)"
        ) from None
    span = password_span(url)
    given = urllib.parse.unquote(url[span[0] : span[1]]) if span else None
    if parsed.password is not None and parsed.password != given:
        raise ValueError(
            f"the storage {redact_url(url)!r} has an '@' in its password, which ends it for SQLAlchemy: "
            "write it percent-encoded, as %40"
        )


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
            storage.set_trial_user_attr(storage_id(trial), REASON_ATTR, why or f"no heartbeat for {now - beat:.0f} s")
            if not storage.set_trial_state_values(storage_id(trial), TrialState.FAIL):
                continue
        except UpdateFinishedTrialError:
            continue
        enqueue_retry(study, storage.get_trial(storage_id(trial)))
        failed.append(trial.number)
    return failed


def reclaim_now(study: optuna.Study, storage: optuna.storages.BaseStorage) -> list[int]:
    """Fail every running trial at once and enqueue its retry (``--reclaim-now``: the caller knows
    their workers are dead); the numbers of the trials failed."""
    failed = fail_stale_trials(study, storage, grace=-math.inf, why="reclaimed at once (--reclaim-now)")
    if failed:
        print(f"roto: reclaimed running trials {failed}: each is retried from its latest checkpoint", flush=True)
    return failed


def wait_for_running(
    study: optuna.Study,
    heartbeat: float,
    told: set[tuple[int, ...]],
    watched: Callable[[optuna.trial.FrozenTrial], bool] = lambda trial: True,
) -> bool:
    """Whether ``watched`` trials still run; if so, wait one heartbeat (saying why, once per set of
    trials).

    A worker with nothing left to claim waits here rather than stopping: a running trial either
    finishes, or its worker has died and the trial is retried once its heartbeat is ``4 *
    heartbeat`` s old, by whichever worker is still looking. ``told``: the sets already announced.
    """
    trials = study.get_trials(deepcopy=False, states=(TrialState.RUNNING,))
    running = tuple(t.number for t in trials if watched(t))
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

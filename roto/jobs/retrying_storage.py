"""A database storage that rides out a database restart instead of crashing the worker.

Every storage call (claims, heartbeats, reports, tells) that fails because the connection is gone
is retried, with growing pauses, for up to ``window_s`` seconds; a restart of the server costs a
worker a pause, not its trial. Errors that are not about the connection (a bad value, a finished
trial) are raised at once. Connection errors that outlast the window are raised as
``DatabaseUnreachable``, whose message names the URL (password hidden) and the driver's reason
instead of Optuna's generic one ("invalid data in the commit"); a role without the privileges
Optuna's tables need gets ``DatabasePermissionDenied``, saying so.

A write the server committed just before the connection dropped may be sent again. A second claim
or ``tell`` of one trial finds it already running or finished, which a worker treats as a trial
another worker took; a trial created twice leaves one copy without a heartbeat, which is failed
and retried after the grace period. Neither loses a finished trial.
"""

from __future__ import annotations

import abc
import contextlib
import sys
import time
from collections.abc import Callable
from typing import Any

import optuna
import sqlalchemy.exc
from optuna.exceptions import StorageInternalError

RETRY_WINDOW_S = 60.0
"""Seconds a storage call keeps retrying a lost connection (a server restart takes a few)."""
FIRST_PAUSE_S = 0.25
MAX_PAUSE_S = 4.0

STORAGE_METHODS = (
    "check_trial_is_updatable",
    "create_new_study",
    "create_new_trial",
    "delete_study",
    "get_all_studies",
    "get_all_trials",
    "get_best_trial",
    "get_n_trials",
    "get_study_directions",
    "get_study_id_from_name",
    "get_study_name_from_id",
    "get_study_system_attrs",
    "get_study_user_attrs",
    "get_trial",
    "get_trial_id_from_study_id_trial_number",
    "get_trial_number_from_id",
    "get_trial_param",
    "get_trial_params",
    "get_trial_system_attrs",
    "get_trial_user_attrs",
    "remove_session",
    "set_study_system_attr",
    "set_study_user_attr",
    "set_trial_intermediate_value",
    "set_trial_param",
    "set_trial_state_values",
    "set_trial_system_attr",
    "set_trial_user_attr",
)
"""``optuna.storages.BaseStorage``'s public methods: each one retries on a lost connection."""


class DatabaseUnreachable(ConnectionError):
    """The database stayed unreachable for the whole retry window (an OSError: the CLI reports it
    in one line, exit code 1)."""


class DatabasePermissionDenied(PermissionError):
    """The database refused the role an operation on Optuna's tables. A PermissionError, so the CLI
    reports it in one line with exit code 2, as a wrong password: the command cannot succeed until
    the role's grants or the URL change, and running it again does not help."""


INSUFFICIENT_PRIVILEGE = "42501"
"""The SQLSTATE of PostgreSQL's "permission denied" (psycopg2's ``pgcode``, psycopg 3's ``sqlstate``)."""
GRANTS_NEEDED = (
    "the role needs SELECT, INSERT, UPDATE and DELETE on Optuna's tables and USAGE on their sequences "
    "(in a new database also CREATE on the schema, to make them)"
)


def permission_error(error: BaseException) -> BaseException | None:
    """The driver's "permission denied" behind ``error`` (Optuna wraps it in StorageInternalError,
    which hides it behind "invalid data in the commit, e.g. exceeding max length"), or None."""
    chain, seen = [error], set()
    while chain:
        found = chain.pop()
        if found is None or id(found) in seen:
            continue
        seen.add(id(found))
        codes = (getattr(found, "pgcode", None), getattr(found, "sqlstate", None))
        if INSUFFICIENT_PRIVILEGE in codes or type(found).__name__ == "InsufficientPrivilege":
            return found
        chain += [found.__cause__, found.__context__, getattr(found, "orig", None)]
    return None


def permission_denied(name: str, cause: BaseException) -> DatabasePermissionDenied:
    """The one-line error for the database named ``name`` (its URL, password hidden) refusing ``cause``."""
    return DatabasePermissionDenied(f"database {name!r}: {first_line(cause)}: {GRANTS_NEEDED}")


def connection_error(error: BaseException) -> BaseException | None:
    """The driver's connection error behind ``error`` (Optuna wraps it in StorageInternalError), or
    None when ``error`` is not about a lost or refused connection."""
    cause = error.__cause__ if isinstance(error, StorageInternalError) else error
    lost = (sqlalchemy.exc.OperationalError, sqlalchemy.exc.InterfaceError, sqlalchemy.exc.PendingRollbackError)
    if isinstance(cause, lost):  # PendingRollbackError: a session whose transaction a lost connection broke
        return cause
    if isinstance(cause, sqlalchemy.exc.DBAPIError) and cause.connection_invalidated:
        return cause
    return None


def first_line(error: BaseException) -> str:
    """The driver's own message, first line (SQLAlchemy appends SQL and a link below it)."""
    return str(getattr(error, "orig", None) or error).strip().splitlines()[0]


class RetryingStorage(optuna.storages.BaseStorage):
    """``inner`` (a database storage) with every call retried across a lost connection.

    Args:
        inner: the storage to call.
        name: how messages name the database (its URL with the password hidden).
        window_s: seconds to keep retrying one call.
        sleep: the pause function (tests pass a fake clock's).
    """

    def __init__(
        self,
        inner: optuna.storages.BaseStorage,
        name: str,
        window_s: float = RETRY_WINDOW_S,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self.inner, self.name, self.window_s, self.sleep = inner, name, window_s, sleep

    def call(self, method: str, *args: Any, **kwargs: Any) -> Any:
        """``inner.<method>(*args, **kwargs)``, retried while the connection is lost."""
        deadline = time.monotonic() + self.window_s
        pause, announced = FIRST_PAUSE_S, False
        while True:
            try:
                return getattr(self.inner, method)(*args, **kwargs)
            except Exception as error:
                denied = permission_error(error)
                if denied is not None:
                    raise permission_denied(self.name, denied) from None
                cause = connection_error(error)
                if cause is None:
                    raise
                if time.monotonic() + pause > deadline:
                    raise DatabaseUnreachable(
                        f"the database {self.name!r} was unreachable for {self.window_s:.0f} s: {first_line(cause)}"
                    ) from None
                if not announced:
                    print(
                        f"roto: database {self.name!r} unreachable ({first_line(cause)}); retrying for up to "
                        f"{self.window_s:.0f} s",
                        file=sys.stderr,
                        flush=True,
                    )
                    announced = True
                self.discard_session()
            self.sleep(pause)
            pause = min(2 * pause, MAX_PAUSE_S)

    def discard_session(self) -> None:
        """Drop this thread's database session (a database storage keeps one per thread): after a
        lost connection it may hold a broken transaction that no later call could get past."""
        sessions = getattr(self.inner, "scoped_session", None)
        if sessions is not None:
            with contextlib.suppress(sqlalchemy.exc.SQLAlchemyError):
                sessions.remove()

    def __getattr__(self, name: str) -> Any:
        """Anything else the inner storage has (its engine, its URL), without retries."""
        if name == "inner":  # not set yet (unpickling): no recursion
            raise AttributeError(name)
        return getattr(self.inner, name)


def _retrying(method: str) -> Callable[..., Any]:
    def call(self: RetryingStorage, *args: Any, **kwargs: Any) -> Any:
        return self.call(method, *args, **kwargs)

    call.__name__ = method
    call.__doc__ = f"``{method}`` of the inner storage, retried while the connection is lost."
    return call


for _method in STORAGE_METHODS:
    setattr(RetryingStorage, _method, _retrying(_method))
abc.update_abstractmethods(RetryingStorage)

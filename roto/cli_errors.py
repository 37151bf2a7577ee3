"""The ``roto`` command's error boundary: which failures are one-line messages, and their exit codes."""

from __future__ import annotations

import os
import pathlib

BAD_PATH_ERRORS = (FileNotFoundError, FileExistsError, IsADirectoryError, NotADirectoryError, PermissionError)


def error_exit(error: Exception) -> tuple[int | None, str]:
    """(exit code, word) for an expected failure: 2 "error" for bad input (a bad value, name or
    path), 1 "failed" for a failure while running (out of memory, an OS or database error); (None,
    "") for an unexpected one, which keeps its traceback (a bug to report)."""
    if isinstance(error, (ValueError, TypeError, KeyError, *BAD_PATH_ERRORS)):
        return 2, "error"
    if isinstance(error, (OSError, MemoryError)):
        return 1, "failed"
    module = type(error).__module__.split(".")[0]
    if module in ("sqlalchemy", "optuna", "psycopg2", "psycopg"):
        return 1, "failed"
    return None, ""


def check_output_file(path: str, flag: str) -> None:
    """Refuse, before any work, an output path that cannot be written as a file."""
    out = pathlib.Path(path)
    if out.is_dir():
        raise ValueError(f"{flag} {path!r} is a directory; give a file path, e.g. {str(out / 'play.mp4')!r}")
    if not out.parent.is_dir():
        what = "is not a directory" if out.parent.exists() else "does not exist"
        raise ValueError(f"{flag} {path!r}: {str(out.parent)!r} {what}")
    if not os.access(out.parent, os.W_OK):
        raise PermissionError(f"{flag} {path!r}: directory {str(out.parent)!r} is not writable")

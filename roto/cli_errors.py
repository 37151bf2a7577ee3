"""The ``roto`` command's error boundary: which failures are one-line messages, and their exit codes."""

from __future__ import annotations

import contextlib
import os
import pathlib
import sys
from collections.abc import Iterator

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


def _nearest_existing(path: pathlib.Path) -> pathlib.Path:
    """``path`` itself if it exists, else its nearest ancestor that does."""
    for candidate in (path, *path.parents):
        if candidate.exists():
            return candidate
    return pathlib.Path(".")  # pragma: no cover (the root or the current directory always exists)


def check_output_path(path: str | os.PathLike, flag: str, kind: str = "file", example: str = "") -> pathlib.Path:
    """Refuse, before any work, an output path that cannot be written as a ``kind`` ("file" or "dir").

    Missing parent directories are fine (the writer creates them, ``make_parents``); refused are a
    directory where a file goes, a file where a directory goes, a file on the way (``a/file/x``) and a
    nearest existing directory this process cannot write into. Creates nothing; returns the path.
    ``example``: a file name the message suggests inside a directory given for a file.
    """
    if kind not in ("file", "dir"):
        raise ValueError(f"kind must be 'file' or 'dir', got {kind!r}")
    out = pathlib.Path(path)
    if kind == "file" and out.is_dir():
        hint = f", e.g. {str(out / example)!r}" if example else ""
        raise ValueError(f"{flag} {str(path)!r} is a directory; give a file path{hint}")
    if kind == "dir" and out.exists() and not out.is_dir():
        raise ValueError(f"{flag} {str(path)!r} is a file; give a directory (an existing one or one to create)")
    existing = _nearest_existing(out if kind == "dir" else out.parent)
    if not existing.is_dir():
        raise ValueError(f"{flag} {str(path)!r}: {str(existing)!r} is not a directory (it is a file)")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise PermissionError(f"{flag} {str(path)!r}: directory {str(existing)!r} is not writable")
    return out


def check_output_file(path: str | os.PathLike, flag: str, example: str = "") -> pathlib.Path:
    """``check_output_path`` of a file."""
    return check_output_path(path, flag, "file", example)


def make_parents(path: str | os.PathLike) -> pathlib.Path:
    """Create the missing parent directories of an output file, right before it is written."""
    out = pathlib.Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    return out


@contextlib.contextmanager
def parents_made(path: str | os.PathLike) -> Iterator[pathlib.Path]:
    """``make_parents`` for a block of work that writes ``path`` at its end: should the block fail, the
    folders it made are removed again (those still empty), so a refusal leaves nothing behind."""
    out = pathlib.Path(path)
    missing = [folder for folder in out.parents if not folder.exists()]  # the nearest first
    make_parents(out)
    try:
        yield out
    except BaseException:
        for folder in missing:
            with contextlib.suppress(OSError):
                folder.rmdir()
        raise


CLOSED_STDOUT_EXIT = 141
"""Exit code when the reader of stdout went away (``roto ... | head -1``): 128 + SIGPIPE, as a shell
reports for a command the signal ended."""


@contextlib.contextmanager
def quiet_on_closed_stdout() -> Iterator[None]:
    """Turn a ``BrokenPipeError`` of stdout (its reader, e.g. ``head``, exited) into a quiet exit with
    ``CLOSED_STDOUT_EXIT``, as the Python docs advise: stdout is pointed at devnull so that the
    interpreter's last flush at exit fails no more. Output still buffered is flushed inside."""
    try:
        try:
            yield
        finally:
            sys.stdout.flush()
    except BrokenPipeError:
        with contextlib.suppress(OSError, ValueError):  # ValueError: a stdout without a file (captured)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        raise SystemExit(CLOSED_STDOUT_EXIT) from None

"""roto's results files (cell summaries, evaluation JSON, tables, plots, exported configs): written
atomically, so a crash or Ctrl-C mid-write leaves the old file or the new one, never half of one;
read with errors that name the file."""

from __future__ import annotations

import contextlib
import json
import os
import pathlib
from collections.abc import Iterator
from typing import Any

from roto.text_files import read_text


@contextlib.contextmanager
def replacing(path: str | pathlib.Path) -> Iterator[pathlib.Path]:
    """Yield a temporary path beside ``path`` to write; on success it replaces ``path`` in one
    rename, on an exception it is removed and ``path`` is untouched."""
    path = pathlib.Path(path)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        yield temporary
        temporary.replace(path)
    finally:
        temporary.unlink(missing_ok=True)


def write_text_atomic(path: str | pathlib.Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically."""
    with replacing(path) as temporary:
        temporary.write_text(text)


def read_json(path: str | pathlib.Path, what: str = "JSON file") -> Any:
    """The data of ``path``.

    Raises:
        FileNotFoundError when it does not exist; ValueError naming ``what`` and the file when it cannot
        be read or is not text (``roto.text_files.read_text``), with the line and column when it is not
        valid JSON.
    """
    text = read_text(path, what, "JSON")
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(
            f"{what} {str(path)!r} is not valid JSON at line {error.lineno}, column {error.colno}: {error.msg}"
        ) from None

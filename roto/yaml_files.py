"""Reading roto's YAML files (agent configs, search spaces, plans, a run's config) with errors that
name the file: a syntax error or an unreadable file becomes a ValueError, never a traceback."""

from __future__ import annotations

import pathlib
from typing import Any

import yaml


def read_yaml(path: str | pathlib.Path, what: str = "YAML file") -> Any:
    """The data of ``path`` (``yaml.safe_load``; an empty file reads as None).

    Raises:
        FileNotFoundError when ``path`` does not exist; ValueError naming ``what`` and the file
        when it cannot be read or is not valid YAML (with the line and column of the problem).
    """
    path = pathlib.Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise FileNotFoundError(f"{what} {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise ValueError(f"{what} {str(path)!r} cannot be read: {reason}") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(error, "problem", None) or "malformed"
        raise ValueError(f"{what} {str(path)!r} is not valid YAML{where}: {problem}") from None

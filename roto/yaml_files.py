"""Reading roto's YAML files (agent configs, search spaces, plans, a run's config) with errors that
name the file: a syntax error, a key given twice or an unreadable file becomes a ValueError, never a
traceback."""

from __future__ import annotations

import pathlib
from typing import Any

import yaml

from roto.text_files import read_text


class _DuplicateKey(yaml.YAMLError):
    """A mapping names one key twice: YAML keeps the last silently, roto refuses it."""


class _UniqueKeyLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses a mapping holding a key twice, naming both lines."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict:
        seen: dict[object, int] = {}
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge" or not isinstance(key_node, yaml.ScalarNode):
                continue  # keys a merge (<<) brings in may be overridden: that is what merging is for
            key, line = self.construct_object(key_node), key_node.start_mark.line + 1
            if key in seen:
                raise _DuplicateKey(f"key {key!r} appears twice in one mapping, at lines {seen[key]} and {line}")
            seen[key] = line
        return super().construct_mapping(node, deep=deep)


def read_yaml(path: str | pathlib.Path, what: str = "YAML file") -> Any:
    """The data of ``path`` (``yaml.safe_load``; an empty file reads as None).

    Raises:
        FileNotFoundError when ``path`` does not exist; ValueError naming ``what`` and the file
        when it cannot be read or is not valid YAML (with the line and column of the problem).
    """
    text = read_text(path, what, "YAML")
    try:
        return yaml.load(text, Loader=_UniqueKeyLoader)  # a SafeLoader: plain data only
    except _DuplicateKey as error:
        raise ValueError(f"{what} {str(path)!r}: {error}") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(error, "problem", None) or "malformed"
        raise ValueError(f"{what} {str(path)!r} is not valid YAML{where}: {problem}") from None

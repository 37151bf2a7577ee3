"""``roto train --help-config``: every key a config file or a ``section.key=value`` override can
set, with its default and its one-line meaning, read from the config dataclasses' own docstrings
(a field's docstring below it, or an ``Attributes:`` entry of the class docstring)."""

from __future__ import annotations

import argparse
import ast
import dataclasses
import inspect
import itertools
import re
import textwrap
import types
import typing
from typing import Any

ATTRIBUTE_ENTRY = re.compile(r"^(\w+): (.*)$")


def attribute_section(docstring: str) -> dict[str, str]:
    """{name: text} of the ``Attributes:`` section of a Google-style class docstring."""
    docs: dict[str, str] = {}
    lines = inspect.cleandoc(docstring).splitlines()
    if "Attributes:" not in lines:
        return docs
    name = None
    for line in lines[lines.index("Attributes:") + 1 :]:
        if not line.strip():
            break
        top_level = line.startswith("    ") and not line.startswith("     ")  # an entry, not its continuation
        entry = ATTRIBUTE_ENTRY.match(line.strip()) if top_level else None
        if entry:
            name = entry.group(1)
            docs[name] = entry.group(2)
        elif name is not None:
            docs[name] += " " + line.strip()
    return docs


def field_docs(cls: type) -> dict[str, str]:
    """{field: its documentation, on one line} of dataclass ``cls``, inherited ones included."""
    docs: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        if not dataclasses.is_dataclass(klass):
            continue
        docs.update(attribute_section(klass.__doc__ or ""))
        try:
            body = ast.parse(textwrap.dedent(inspect.getsource(klass))).body[0].body
        except (OSError, TypeError):  # no source (a frozen install): the Attributes sections remain
            continue
        for statement, following in itertools.pairwise(body):
            documented = isinstance(following, ast.Expr) and isinstance(following.value, ast.Constant)
            if isinstance(statement, ast.AnnAssign) and isinstance(statement.target, ast.Name) and documented:
                docs[statement.target.id] = str(following.value.value)
    return {name: " ".join(text.split()) for name, text in docs.items()}


def nested_dataclass(annotation: Any) -> type | None:
    """The dataclass an annotation holds (``X`` or ``X | None``), else None."""
    if typing.get_origin(annotation) is types.UnionType:
        inner = [a for a in typing.get_args(annotation) if a is not type(None)]
        annotation = inner[0] if len(inner) == 1 else None
    return annotation if dataclasses.is_dataclass(annotation) else None


class Required:
    """The default shown for a setting a section needs a value for (``required``)."""

    def __repr__(self) -> str:
        return "required"


REQUIRED = Required()


def default_of(field: dataclasses.Field) -> Any:
    """A field's default value (``REQUIRED`` when it has none)."""
    if field.default is not dataclasses.MISSING:
        return field.default
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return REQUIRED


def config_keys(cls: type, prefix: str = "", skip: tuple[str, ...] = ()) -> list[tuple[str, Any, str]]:
    """(dotted key, default, documentation) of every settable key under dataclass ``cls``."""
    hints, docs = typing.get_type_hints(cls), field_docs(cls)
    rows = []
    for field in dataclasses.fields(cls):
        if field.name in skip:
            continue
        key, nested = f"{prefix}{field.name}", nested_dataclass(hints[field.name])
        if nested is not None and field.default is None:  # an optional section, off by default
            summary = " ".join(inspect.cleandoc(nested.__doc__ or "").split("\n\n")[0].split())
            rows.append((key, None, docs.get(field.name, "") or f"on when set: {summary}"))
            rows += config_keys(nested, f"{key}.")
        elif nested is not None:
            rows += config_keys(nested, f"{key}.")
        else:
            rows.append((key, default_of(field), docs.get(field.name, "")))
    return rows


def help_config() -> str:
    """The text ``roto train --help-config`` prints."""
    from roto.envs.config import EnvConfig
    from roto.rl.config import AgentConfig
    from roto.rl.overrides import FIXED_ENV_KEYS

    def block(rows: list[tuple[str, Any, str]]) -> list[str]:
        width = max(len(key) for key, _, _ in rows)
        return [f"  {key:<{width}}  {default!r:>10}  {doc}" for key, default, doc in rows]

    lines = ["Agent config keys (a YAML file's sections, or section.key=value overrides), with their defaults:"]
    lines += block(config_keys(AgentConfig))
    lines += [
        "",
        "Env keys (env.key=value overrides; task, robot and obs mode are the run's own flags; the training aids,"
        " env.aids.<aid>.<setting>, may also be set in an agent config's training_aids section as"
        " <aid>: {<setting>: value}, {robot} standing for the hand):",
    ]
    lines += block(config_keys(EnvConfig, "env.", skip=FIXED_ENV_KEYS))
    return "\n".join(lines)


class HelpConfigAction(argparse.Action):
    """``--help-config``: print ``help_config()`` and exit, as ``--help`` does."""

    def __init__(self, option_strings: list[str], dest: str, **kwargs: Any) -> None:
        kwargs.setdefault("help", "list every agent and env config key with its default and meaning, and exit")
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, *args: Any) -> None:
        print(help_config())
        parser.exit()

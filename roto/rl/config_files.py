"""Agent config files: packaged configs and YAML files, their ``extends:`` chains, ``key=value``
overrides and the ``training_aids`` section, read into ``roto.rl.config.AgentConfig``.

A file may start from another with ``extends: NAME`` and list only what it changes. An optional
``training_aids`` section switches on training aids (the env's ``aids`` section,
``roto.envs.aids.settings``) that the run's training envs use and evaluation never does.
``key=value`` overrides (e.g. ``ppo.lr=1e-4``, ``ssl.forward_dynamics.weight=0.01``) are applied on
top, with the value parsed as YAML.
"""

from __future__ import annotations

import importlib.resources
import pathlib
from typing import Any

import yaml

from roto.envs.aids.settings import LEGACY_FIELDS
from roto.rl.config import AgentConfig, from_dict
from roto.yaml_files import read_yaml


def parse_override(item: str) -> tuple[str, Any]:
    """``section.key=value`` -> (dotted key, value parsed as YAML)."""
    key, sep, raw = item.partition("=")
    if not sep or not key:
        raise ValueError(f"override {item!r} must look like section.key=value (e.g. ppo.lr=1e-4)")
    try:
        return key, yaml.safe_load(raw)
    except yaml.YAMLError:
        raise ValueError(f"override {item!r}: the value {raw!r} is not valid YAML") from None


def apply_overrides(data: dict[str, Any], overrides: list[str]) -> dict[str, Any]:
    """Apply ``section.key=value`` overrides to a nested dict (a new dict is returned)."""
    merged = yaml.safe_load(yaml.safe_dump(data)) or {}
    for item in overrides:
        key, value = parse_override(item)
        node = merged
        *parents, leaf = key.split(".")
        for part in parents:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise ValueError(f"override {item!r}: {part!r} is not a section")
        node[leaf] = value
    return merged


def packaged_configs() -> dict[str, pathlib.Path]:
    """{name: path} of the agent configs shipped in ``roto/configs`` (e.g. ``bounce_forward_dynamics``)."""
    folder = importlib.resources.files("roto") / "configs"
    return {pathlib.Path(str(p)).stem: pathlib.Path(str(p)) for p in folder.iterdir() if p.name.endswith(".yaml")}


def resolve_config_path(task: str, path: str | pathlib.Path | None) -> pathlib.Path:
    """The YAML file a ``--agent_cfg`` value means: a file, a packaged config's name, or (None) the task's default."""
    shipped = packaged_configs()
    if path is None:
        if task not in shipped:
            raise ValueError(f"task {task!r} has no packaged default agent config (roto/configs/{task}.yaml); name one")
        return shipped[task]
    source = pathlib.Path(path)
    if source.is_file():
        return source
    if str(path) in shipped:
        return shipped[str(path)]
    raise FileNotFoundError(
        f"agent config {str(path)!r} does not exist; give a YAML file or a packaged config: {sorted(shipped)}"
    )


EXTENDS = "extends"
"""Top-level key of an agent config naming the config it changes (a packaged name or a file)."""
TRAINING_AIDS = "training_aids"
"""Top-level section of an agent config with the training envs' aids (the env's ``aids`` section)."""


def merge(base: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
    """``base`` with ``changes`` on top: sections merge key by key, any other value replaces."""
    merged = dict(base)
    for key, value in changes.items():
        both_sections = isinstance(value, dict) and isinstance(merged.get(key), dict)
        merged[key] = merge(merged[key], value) if both_sections else value
    return merged


def read_agent_data(config_path: pathlib.Path, chain: tuple[pathlib.Path, ...] = ()) -> dict[str, Any]:
    """The settings of the agent config at ``config_path``, its ``extends:`` chain resolved.

    ``extends: NAME`` names a packaged config or a YAML file (relative to this file's folder); the
    file then lists only what it changes. Raises ValueError for an empty file, a cycle, or a base
    that does not exist (naming the extending file).
    """
    data = read_yaml(config_path, "agent config")
    if data is None:
        raise ValueError(f"agent config {str(config_path)!r} is empty; it would train on defaults it never names")
    if not isinstance(data, dict) or EXTENDS not in data:
        return data
    data = dict(data)
    base_name = str(data.pop(EXTENDS))
    beside = config_path.parent / base_name
    shipped = packaged_configs()
    if beside.is_file():
        base_path = beside
    elif base_name in shipped:
        base_path = shipped[base_name]
    else:
        raise ValueError(
            f"agent config {str(config_path)!r} extends {base_name!r}, which is neither a file beside it nor a "
            f"packaged config: {sorted(shipped)}"
        )
    if base_path.resolve() in chain or base_path.resolve() == config_path.resolve():
        names = " -> ".join(str(p) for p in (*chain, config_path.resolve(), base_path.resolve()))
        raise ValueError(f"agent configs extend each other in a circle: {names}")
    return merge(read_agent_data(base_path, (*chain, config_path.resolve())), data)


def load_agent_config(
    task: str, path: str | pathlib.Path | None = None, overrides: list[str] | None = None
) -> AgentConfig:
    """The task's default config, or ``path`` (a YAML file or packaged name), with ``overrides``;
    validated. Its ``training_aids`` section is the env's (``load_training_aids``)."""
    data = read_agent_data(resolve_config_path(task, path))
    if isinstance(data, dict):  # anything else: from_dict says it must be a mapping
        data = {key: value for key, value in data.items() if key != TRAINING_AIDS}
    data = apply_overrides(data, overrides or [])
    return from_dict(AgentConfig, data).validate()


def load_training_aids(task: str, path: str | pathlib.Path | None, robot: str) -> dict[str, Any]:
    """The config's ``training_aids`` section ({} without one): the env's ``aids`` section
    ({aid: {setting: value}}, ``roto.envs.aids.settings``) with ``{robot}`` in a text value
    replaced by ``robot`` (e.g. a per-hand bank of recorded starts). Its aids and settings are
    checked when the env config is built."""
    config_path = resolve_config_path(task, path)
    data = read_agent_data(config_path)
    aids = (data.get(TRAINING_AIDS) if isinstance(data, dict) else None) or {}
    where = f"agent config {str(config_path)!r}: {TRAINING_AIDS}"
    if not isinstance(aids, dict):
        raise ValueError(f"{where} must be a mapping of aids to their settings, got {aids!r}")
    flat = sorted(set(aids) & set(LEGACY_FIELDS))
    if flat:
        spelled = [".".join(LEGACY_FIELDS[name]) for name in flat]
        raise ValueError(f"{where}: {flat} are now set per aid, as {spelled} (roto.envs.aids.settings)")

    def for_robot(value: Any) -> Any:
        if isinstance(value, dict):
            return {key: for_robot(item) for key, item in value.items()}
        return value.replace("{robot}", robot) if isinstance(value, str) else value

    return for_robot(aids)

"""A run directory's ``config.yaml``: the run's ``RunSpec`` (its envs, agent and budget), every
key spelled out, stamped with its format."""

from __future__ import annotations

import pathlib
from typing import Any

import yaml

from roto.artifact_formats import FORMAT_KEY, check_format, format_stamp
from roto.result_files import write_text_atomic
from roto.rl.run_spec import RunSpec
from roto.yaml_files import read_yaml

CONFIG_NAME = "config.yaml"


def run_config(spec: RunSpec) -> dict[str, Any]:
    """The resolved config of a run as a plain nested dict: {"format", "env", "agent", "steps"}."""
    return {**format_stamp("run config"), **spec.to_dict()}


def write_run_config(run_dir: pathlib.Path, spec: RunSpec) -> None:
    """The resolved config of a run (what ``--resume`` reads back)."""
    write_text_atomic(run_dir / CONFIG_NAME, yaml.safe_dump(run_config(spec), sort_keys=False))


def read_run_config(run_dir: pathlib.Path) -> RunSpec:
    """Inverse of ``write_run_config`` (an older layout read too, ``roto.rl.run_spec.spec_data``)."""
    path = run_dir / CONFIG_NAME
    if not path.is_file():
        raise FileNotFoundError(f"{str(run_dir)!r} is not a roto run directory (no {CONFIG_NAME})")
    data = read_yaml(path, "run config")
    if not isinstance(data, dict) or not ({"env", "agent"} <= set(data) or {"train", "agent"} <= set(data)):
        raise ValueError(f"run config {str(path)!r} is not a roto run config (no 'env' and 'agent' sections)")
    check_format("run config", data.get(FORMAT_KEY), f"run config {str(path)!r}")
    return RunSpec.from_dict(data)

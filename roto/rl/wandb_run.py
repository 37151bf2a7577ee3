"""Weights & Biases logging (``roto train --logger wandb``; the optional extra ``pip install -e '.[wandb]'``).

A run directory that logs to W&B keeps its W&B project and run id in ``wandb.yaml``, so resuming it
continues the same W&B run. W&B's own files go under ``<run_dir>/wandb/``; the standard ``WANDB_*``
environment variables apply (``WANDB_MODE=offline`` needs no network or account: ``wandb sync`` later).
"""

from __future__ import annotations

import importlib.util
import pathlib
from typing import Any

import yaml

from roto.result_files import write_text_atomic
from roto.yaml_files import read_yaml

WANDB_FILE = "wandb.yaml"


def require_wandb() -> None:
    """A clear error, before anything is written, when the ``wandb`` package is missing."""
    if importlib.util.find_spec("wandb") is None:
        raise ValueError("logging to Weights & Biases needs wandb, which is not installed: pip install -e '.[wandb]'")


def read_wandb_file(path: pathlib.Path) -> dict[str, Any]:
    """``wandb.yaml``'s project and run id; ValueError naming the file when it is malformed."""
    data = read_yaml(path, "W&B run file")
    if not isinstance(data, dict) or not {"project", "id"} <= data.keys():
        raise ValueError(f"W&B run file {str(path)!r} must hold 'project' and 'id', got {data!r}")
    return data


def logged_wandb_project(run_dir: pathlib.Path) -> str | None:
    """The W&B project ``run_dir`` logs to (None: it does not log to W&B)."""
    path = run_dir / WANDB_FILE
    return read_wandb_file(path)["project"] if path.is_file() else None


def open_wandb_run(run_dir: pathlib.Path, project: str, config: dict[str, Any]) -> Any:
    """Start ``run_dir``'s W&B run in ``project``, or continue it (in its own project) if ``wandb.yaml`` exists."""
    import wandb

    path = run_dir / WANDB_FILE
    stored = read_wandb_file(path) if path.is_file() else {"project": project, "id": None}
    run = wandb.init(
        project=stored["project"], id=stored["id"], name=run_dir.name, dir=run_dir, config=config, resume="allow"
    )
    write_text_atomic(path, yaml.safe_dump({"project": run.project, "id": run.id}, sort_keys=False))
    return run

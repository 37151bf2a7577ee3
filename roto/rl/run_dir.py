"""A run directory's layout and its readers, in one place.

``<run_dir>/config.yaml`` (``roto.rl.run_config``), ``scalars.csv``, ``evaluations.jsonl``,
``tensorboard/`` and ``checkpoints/``: ``latest.pt`` (everything a resume needs), ``best.pt`` and
the numbered copies ``agent_<update>.pt`` (the policy only, ``POLICY_KEYS``). ``load_policy``
reads any of them without building an env (checking its labels against its run's ``config.yaml``);
``RunDir`` gathers the readers of one run.
"""

from __future__ import annotations

import csv
import pathlib
from dataclasses import dataclass
from typing import Any

from roto.rl.build import build_model
from roto.rl.checkpoints import load_checkpoint
from roto.rl.evaluation import read_evaluations
from roto.rl.logger import CSV_NAME
from roto.rl.networks import ActorCritic
from roto.rl.run_config import read_run_config
from roto.rl.run_spec import RunSpec

CHECKPOINT_DIR = "checkpoints"
POLICY_KEYS = ("format", "model", "spec", "obs_sizes", "num_actions", "update", "env_steps")
POLICY_KEYS += ("best_eval", "last_eval")
"""What a policy-only checkpoint holds: enough for ``load_policy``, ``roto eval`` and ``roto play``."""


def checkpoint_path(run_dir: str | pathlib.Path, name: str = "latest") -> pathlib.Path:
    """``<run_dir>/checkpoints/<name>.pt`` (``latest``, ``best`` or ``agent_<update>``)."""
    return pathlib.Path(run_dir) / CHECKPOINT_DIR / f"{name}.pt"


def numbered_checkpoints(run_dir: pathlib.Path) -> list[pathlib.Path]:
    """The run's ``agent_<update>.pt`` copies, oldest first."""
    paths = (run_dir / CHECKPOINT_DIR).glob("agent_*.pt")
    return sorted((p for p in paths if p.stem[6:].isdigit()), key=lambda p: int(p.stem[6:]))


def first_missing(path: pathlib.Path) -> pathlib.Path | None:
    """The outermost of ``path`` and its parents that does not exist yet (None: ``path`` exists)."""
    missing = None
    for folder in (path, *path.parents):
        if folder.exists():
            break
        missing = folder
    return missing


def load_policy(checkpoint: str | pathlib.Path) -> tuple[ActorCritic, RunSpec]:
    """The policy stored in a checkpoint (on the CPU, in eval mode), with the run's spec."""
    state = load_checkpoint(checkpoint)
    spec = RunSpec.from_dict(state.get("spec") or state)  # formats 1 and 2: "train" and "agent"
    _check_run_labels(pathlib.Path(checkpoint), spec)
    if "obs_sizes" not in state:
        raise ValueError(f"{str(checkpoint)!r} predates checkpoints that name their observation sizes; retrain it")
    sizes, num_actions = {k: int(v) for k, v in state["obs_sizes"].items()}, int(state["num_actions"])
    model = build_model(sizes, num_actions, spec.agent, spec.env.obs_mode)
    model.load_state_dict(state["model"])
    model.eval()
    return model, spec


def _check_run_labels(checkpoint: pathlib.Path, spec: RunSpec) -> None:
    """Refuse a checkpoint inside a run directory whose task, robot or obs mode differ from the
    run's own ``config.yaml`` (a checkpoint relabelled, or copied into another run)."""
    config = checkpoint.parent.parent / "config.yaml"
    if checkpoint.parent.name != CHECKPOINT_DIR or not config.is_file():
        return
    run = read_run_config(checkpoint.parent.parent).env
    keys = ("task", "robot", "obs_mode")
    differ = {k: (getattr(spec.env, k), getattr(run, k)) for k in keys if getattr(spec.env, k) != getattr(run, k)}
    if differ:
        raise ValueError(
            f"checkpoint {str(checkpoint)!r} names {differ} (checkpoint, run), unlike its run's {str(config)!r}: "
            "it was relabelled or copied from another run"
        )


def read_scalars(run_dir: str | pathlib.Path) -> dict[str, tuple[list[int], list[float]]]:
    """{tag: (env_steps, values)} from ``<run_dir>/scalars.csv``."""
    series: dict[str, tuple[list[int], list[float]]] = {}
    with (pathlib.Path(run_dir) / CSV_NAME).open() as f:
        for row in csv.DictReader(f):
            steps, values = series.setdefault(row["tag"], ([], []))
            steps.append(int(row["env_steps"]))
            values.append(float(row["value"]))
    return series


@dataclass(frozen=True)
class RunDir:
    """A run directory and its readers: everything ``roto train`` writes, read back."""

    path: pathlib.Path

    def config(self) -> RunSpec:
        """The run's spec: its envs, agent and budget (``config.yaml``)."""
        return read_run_config(self.path)

    def evaluations(self) -> list[dict[str, Any]]:
        """Every training-time evaluation record (``evaluations.jsonl``), oldest first."""
        return read_evaluations(self.path)

    def scalars(self) -> dict[str, tuple[list[int], list[float]]]:
        """{tag: (env_steps, values)} of every logged scalar (``scalars.csv``)."""
        return read_scalars(self.path)

    def checkpoint(self, name: str = "latest") -> pathlib.Path:
        """The path of checkpoint ``name`` (``latest``, ``best``, ``agent_<update>``)."""
        return checkpoint_path(self.path, name)

    def has_checkpoint(self, name: str = "latest") -> bool:
        """Whether checkpoint ``name`` exists (``latest``: whether the run can be continued)."""
        return self.checkpoint(name).is_file()

    def policy(self, name: str = "best") -> tuple[ActorCritic, RunSpec]:
        """The policy of checkpoint ``name`` with the run's spec (``load_policy``: no env built)."""
        return load_policy(self.checkpoint(name))

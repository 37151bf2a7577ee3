"""A sweep's settings: what it searches and how (the command line's defaults are these fields').

Kept apart from Optuna (``roto.sweep.study``), so building the ``roto`` parser imports no Optuna.
"""

from __future__ import annotations

import pathlib
import re
from dataclasses import dataclass, fields
from typing import Any

from roto.envs.config import EnvConfig
from roto.jobs.flags import HEARTBEAT_S
from roto.tasks import get_task

STUDY_NAME = re.compile(r"[A-Za-z0-9._-]+")
"""A study name: one folder name under ``--root``, nothing that climbs out of it."""

OBJECTIVES = ("return", "metric")
"""What trials maximise, on any task: the best evaluation's mean return, or the task's headline
metric with the return breaking ties; a task's other evaluation metrics may be named too
(``objectives_of``, ``roto.sweep.trial.objective_value``)."""


@dataclass(frozen=True, kw_only=True)
class SweepSettings:
    """What a sweep searches and how; the fields of ``identity()`` must match for workers to join."""

    study: str
    task: str = "bounce"
    robot: str = "shadow"
    obs: str = "blind"
    agent_cfg: str | None = None
    """Base agent config (a YAML file or packaged name; None: the task's default)."""
    overrides: tuple[str, ...] = ()
    """``section.key=value`` overrides every trial gets (env and agent keys) under the searched ones."""
    space: str = "roto2"
    objective: str = "return"
    """``return``, ``metric`` (the task's headline metric), or one of the task's metrics (``objectives_of``)."""
    trials: int = 40
    """Trials that finish (complete or pruned); failed ones are retried or replaced. Not part of the
    study's identity: rerunning with a larger count extends the study."""
    startup: int = 8
    """Random start-up trials of the TPE sampler; the pruner also waits for this many trials."""
    steps: int = 2_500_000
    """Env steps per trial."""
    warmup_steps: int | None = None
    """Env steps before a trial may be pruned (None: a fifth of ``steps``)."""
    num_envs: int = 128
    threads: int = 1
    root: str = "runs/sweeps"
    storage: str | None = None
    """Database URL; None: the journal file in the study's folder."""
    heartbeat: float = HEARTBEAT_S
    """Seconds between a running trial's heartbeats; a trial silent for 4 of them is declared dead."""

    def __post_init__(self) -> None:
        """Reject values no sweep can use."""
        check_study_name(self.study)
        valid = objectives_of(self.task)
        if self.objective not in valid:
            raise ValueError(f"unknown objective {self.objective!r} for task {self.task!r}; valid objectives: {valid}")
        for name in ("trials", "steps", "num_envs", "threads"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if self.startup < 0 or self.heartbeat <= 0:
            raise ValueError(f"startup must be >= 0 and heartbeat > 0, got {self.startup}, {self.heartbeat}")

    @property
    def study_dir(self) -> pathlib.Path:
        """The study's folder: journal, and one run directory per trial."""
        return pathlib.Path(self.root) / self.study

    def base_env(self, seed: int = 0) -> EnvConfig:
        """The trials' env config before overrides and searched env parameters."""
        return EnvConfig(
            task=self.task, robot=self.robot, obs_mode=self.obs, num_envs=self.num_envs, seed=seed, threads=self.threads
        )

    def identity(self) -> dict[str, Any]:
        """The settings that define the study's trials (stored on the study, checked on joining)."""
        keep = ("task", "robot", "obs", "agent_cfg", "overrides", "space", "objective", "steps", "num_envs")
        data = {k: getattr(self, k) for k in keep}
        data["overrides"] = list(self.overrides)
        return data


def objectives_of(task: str) -> list[str]:
    """What a sweep of ``task`` may maximise: ``OBJECTIVES``, then each metric its evaluations
    report (e.g. Baoding's ``round_rotations``: rotations its pair's net turning backs), with the
    return breaking ties."""
    found = get_task(task)
    return [*OBJECTIVES, *found.metric_names, *found.path_metric_names]


def check_study_name(name: str) -> None:
    """Refuse a study name that is not a plain name (it names a folder under ``--root``)."""
    if not isinstance(name, str) or not STUDY_NAME.fullmatch(name) or set(name) == {"."}:
        raise ValueError(
            f"the study name must be a plain name (letters, digits, '.', '_', '-'; not '.' or '..'), got {name!r}"
        )


def sweep_defaults() -> dict[str, Any]:
    """{field: default} of ``SweepSettings``: what the command line gives a flag it is not given."""
    return {f.name: f.default for f in fields(SweepSettings) if f.name != "study"}

"""A sweep's settings and its Optuna study (TPE, median pruner), shared by every worker."""

from __future__ import annotations

import pathlib
import random
import re
from dataclasses import dataclass
from typing import Any

import optuna

from roto.envs.config import EnvConfig
from roto.jobs.storage import JOURNAL_NAME, find_study, open_storage, redact_url
from roto.sweep.pruner import MedianBestSoFarPruner
from roto.tasks import get_task

STUDY_NAME = re.compile(r"[A-Za-z0-9._-]+")
"""A study name: one folder name under ``--root``, nothing that climbs out of it."""

SEEDS = (0, 1, 2, 3, 4)
"""Each trial trains with one of these seeds, drawn per trial (docs/spec.md §8)."""
SETTINGS_ATTR = "roto:settings"
OBJECTIVES = ("return", "metric")
"""What trials maximise, on any task: the best evaluation's mean return, or the task's headline
metric with the return breaking ties; a task's other evaluation metrics may be named too
(``objectives_of``, ``roto.sweep.trial.objective_value``)."""
TIE_BREAK = 1e-6
"""The weight of the mean return in the ``metric`` objective: below the smallest step of a mean
over 100 episodes of a counted metric (0.5 / 100 rotations) for returns up to 5000."""

IDENTITY_DEFAULTS = {"objective": "return"}
"""Identity fields added since studies were first stored: a stored study without one had this."""


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
    heartbeat: float = 30.0
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
        return EnvConfig(task=self.task, robot=self.robot, obs_mode=self.obs, num_envs=self.num_envs, seed=seed,
                         threads=self.threads)  # fmt: skip

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


def trial_seed(study: str, number: int) -> int:
    """The seed trial ``number`` of ``study`` trains with (drawn from ``SEEDS``, reproducibly)."""
    return random.Random(f"{study}:{number}").choice(SEEDS)


def open_study(settings: SweepSettings) -> tuple[optuna.Study, optuna.storages.BaseStorage]:
    """Create the study, or join it when it exists (its stored settings must match these). The
    base run is checked first (its agent config, overrides and bank), so a refused sweep creates
    no study that would then hold the name."""
    from roto.rl.run_spec import build_run_spec

    base = (settings.task, settings.robot, settings.obs, settings.agent_cfg, settings.overrides, settings.steps)
    build_run_spec(*base, num_envs=settings.num_envs, threads=settings.threads)
    storage = open_storage(settings.study_dir, settings.storage)
    # constant liar: parallel workers' running trials count as bad, so they do not all sample the same region
    sampler = optuna.samplers.TPESampler(multivariate=True, n_startup_trials=settings.startup, constant_liar=True)
    warmup = settings.warmup_steps if settings.warmup_steps is not None else settings.steps // 5
    pruner = MedianBestSoFarPruner(n_startup_trials=settings.startup, n_warmup_steps=warmup)
    study = optuna.create_study(
        study_name=settings.study,
        storage=storage,
        sampler=sampler,
        pruner=pruner,
        direction="maximize",
        load_if_exists=True,
    )
    stored = study.user_attrs.get(SETTINGS_ATTR)
    if stored is None:
        study.set_user_attr(SETTINGS_ATTR, settings.identity())
        return study, storage
    stored = {**IDENTITY_DEFAULTS, **stored}
    differ = {k: (stored.get(k), v) for k, v in settings.identity().items() if stored.get(k) != v}
    if differ:
        raise ValueError(
            f"study {settings.study!r} exists with other settings (stored, given): {differ}; "
            "use another --study name or the study's settings"
        )
    return study, storage


def enqueue_base(study: optuna.Study, settings: SweepSettings, space: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    """Enqueue the base run (the study's agent config and fixed overrides) as the study's first
    trial: each searched parameter at the base's value where its distribution can draw it, drawn
    as usual where not. Only into a study without trials (ValueError otherwise); returns
    (the enqueued values, the base values outside the space)."""
    from roto.rl.config import load_agent_config
    from roto.rl.overrides import split_overrides
    from roto.rl.run_spec import training_env
    from roto.sweep.space import base_values

    if study.trials:
        raise ValueError(
            f"--enqueue_base: study {settings.study!r} already has {len(study.trials)} trials; the base run is "
            "enqueued only as a new study's first trial"
        )
    env_changes, agent_overrides = split_overrides(list(settings.overrides))
    env = training_env(settings.base_env(), settings.agent_cfg, env_changes)
    inside, outside = base_values(space, env, load_agent_config(settings.task, settings.agent_cfg, agent_overrides))
    study.enqueue_trial(inside)
    return inside, outside


def check_study_name(name: str) -> None:
    """Refuse a study name that is not a plain name (it names a folder under ``--root``)."""
    if not isinstance(name, str) or not STUDY_NAME.fullmatch(name) or set(name) == {"."}:
        raise ValueError(
            f"the study name must be a plain name (letters, digits, '.', '_', '-'; not '.' or '..'), got {name!r}"
        )


def load_existing_study(name: str, root: str, storage_url: str | None) -> tuple[optuna.Study, dict[str, Any]]:
    """An existing study and its stored settings (for ``export`` and ``show``)."""
    check_study_name(name)
    study = find_study(pathlib.Path(root) / name, name, storage_url)
    if study is None and storage_url is not None:
        raise ValueError(f"no study {name!r} in the storage {redact_url(storage_url)!r}")
    if study is None:
        found = sorted(p.parent.name for p in pathlib.Path(root).glob(f"*/{JOURNAL_NAME}"))
        raise ValueError(f"no study {name!r} under {root!r}; studies there: {found}")
    return study, study.user_attrs.get(SETTINGS_ATTR, {})

"""A sweep's Optuna study (TPE, median pruner), shared by every worker; its settings are
``roto.sweep.settings``'."""

from __future__ import annotations

import pathlib
import random
from typing import Any

import optuna

from roto.jobs.storage import JOURNAL_NAME, find_study, open_storage, redact_url
from roto.sweep.pruner import MedianBestSoFarPruner
from roto.sweep.settings import SweepSettings, check_study_name

SEEDS = (0, 1, 2, 3, 4)
"""Each trial trains with one of these seeds, drawn per trial (docs/spec.md §8)."""
SETTINGS_ATTR = "roto:settings"
TIE_BREAK = 1e-6
"""The weight of the mean return in the ``metric`` objective: below the smallest step of a mean
over 100 episodes of a counted metric (0.5 / 100 rotations) for returns up to 5000."""

IDENTITY_DEFAULTS = {"objective": "return"}
"""Identity fields added since studies were first stored: a stored study without one had this."""


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
    from roto.rl.config_files import load_agent_config
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

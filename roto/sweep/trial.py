"""One sweep trial: an ordinary training run whose evaluations feed the pruner.

The trial's run directory is ``<study folder>/trial_<number>`` (a retried trial continues the run
directory of the trial it retries, from its latest checkpoint), so ``roto eval``, ``roto play`` and
``roto train --resume`` work on any trial. The objective is the best evaluation of the run
(``objective_value``: its mean return, or the task's headline metric with the return breaking
ties); after each evaluation the best so far is reported at the run's env steps, and the median
pruner may stop the trial there. A trial whose loss or weights stop being finite ends pruned, the
reason stored on the trial.
"""

from __future__ import annotations

import math
import pathlib
from collections.abc import Callable
from typing import Any

import optuna
import torch

from roto.envs.config import EnvConfig
from roto.envs.roto_env import RotoEnv
from roto.jobs.storage import RETRY_OF_ATTR
from roto.rl.evaluation import read_evaluations
from roto.rl.run_lock import wait_until_free
from roto.rl.run_spec import RunSpec, build_run_spec
from roto.rl.runner import Trainer
from roto.sweep.settings import SweepSettings
from roto.sweep.space import SearchSpace, as_overrides
from roto.sweep.study import TIE_BREAK, trial_seed


def objective_value(record: dict[str, float], objective: str, headline_metric: str) -> float:
    """What a trial maximises from one evaluation record (``evaluations.jsonl``): its mean return
    (``return``), or the mean of a metric plus ``TIE_BREAK`` x the mean return: the task's
    ``headline_metric`` for ``metric`` (Baoding's rotations), else the metric ``objective`` names
    (Baoding's ``round_rotations``); the dense return tells apart trials that rotate alike."""
    if objective == "return":
        return record["return_mean"]
    name = headline_metric if objective == "metric" else objective
    return record[f"{name}_mean"] + TIE_BREAK * record["return_mean"]


class Diverged(optuna.TrialPruned):
    """A trial's loss or weights are no longer finite (it ends pruned, this the reason)."""


def run_dir_of(settings: SweepSettings, number: int) -> pathlib.Path:
    """The run directory of trial ``number``."""
    return settings.study_dir / f"trial_{number:04d}"


class TrialMonitor:
    """``Trainer.train``'s per-update hook: divergence checks, evaluation reports, pruning."""

    def __init__(self, trial: optuna.Trial, value: Callable[[dict[str, float]], float]) -> None:
        """``value``: an evaluation record's objective (``objective_value`` of the study's objective)."""
        self.trial, self.value, self.best = trial, value, -math.inf

    def __call__(self, trainer: Trainer, scalars: dict[str, float]) -> None:
        """Raise ``Diverged`` or ``optuna.TrialPruned`` to end the trial."""
        bad = {k: v for k, v in scalars.items() if k.startswith("loss/") and not math.isfinite(v)}
        if bad:
            raise Diverged(f"non-finite loss at update {trainer.update}: {bad}")
        if "eval/return_mean" not in scalars:
            return
        if not all(bool(torch.isfinite(p).all()) for p in trainer.model.parameters()):
            raise Diverged(f"non-finite weights at update {trainer.update}")
        record = {k.removeprefix("eval/"): v for k, v in scalars.items() if k.startswith("eval/")}
        self.best = max(self.best, self.value(record))
        self.trial.report(self.best, trainer.env_steps)
        if self.trial.should_prune():
            raise optuna.TrialPruned(
                f"pruned at {trainer.env_steps} env steps: best evaluation {self.best:.6g} is below the median"
            )


def trial_spec(settings: SweepSettings, params: dict[str, Any], seed: int) -> RunSpec:
    """What a trial trains: the study's run with its fixed overrides, then the drawn parameters; the
    trial's seed wins over any ``env.seed`` override."""
    spec = build_run_spec(
        settings.task,
        settings.robot,
        settings.obs,
        settings.agent_cfg,
        [*settings.overrides, *as_overrides(params)],
        settings.steps,
        num_envs=settings.num_envs,
        threads=settings.threads,
    )
    return spec.with_seed(seed)


def run_trial(
    trial: optuna.Trial,
    settings: SweepSettings,
    space: SearchSpace,
    system_attrs: dict[str, Any],
    env_factory: Callable[[EnvConfig], Any] = RotoEnv,
) -> float:
    """Train the trial's run (or continue the run of the trial it retries); its best evaluation's
    objective value.

    ``system_attrs``: the trial's system attributes (a retry names the trial it retries there).
    """
    params = space.suggest(trial)
    retried = system_attrs.get(RETRY_OF_ATTR)  # the retry callback's record of the first try
    number = trial.number if retried is None else int(retried)
    run_dir = run_dir_of(settings, number)
    seed = trial_seed(settings.study, number)
    trial.set_user_attr("seed", seed)
    trial.set_user_attr("run_dir", str(run_dir))
    wait_until_free(run_dir)  # a retry of a trial whose first worker, declared dead, is still training it
    with Trainer.open(run_dir, trial_spec(settings, params, seed), env_factory=env_factory) as trainer:
        headline = getattr(trainer.env.task, "headline_metric", None)
        monitor = TrialMonitor(trial, lambda record: objective_value(record, settings.objective, headline))
        for record in read_evaluations(run_dir):  # a retry: the earlier try's reports, on this trial
            monitor.best = max(monitor.best, monitor.value(record))
            trial.report(monitor.best, record["env_steps"])
        try:
            trainer.train(progress=False, on_update=monitor)
        except (ValueError, RuntimeError) as error:
            # non-finite weights make non-finite actions, which the env refuses before the hook sees them
            if all(bool(torch.isfinite(p).all()) for p in trainer.model.parameters()):
                raise
            raise Diverged(f"non-finite weights at update {trainer.update}: {error}") from error
    return max(monitor.value(record) for record in read_evaluations(run_dir))

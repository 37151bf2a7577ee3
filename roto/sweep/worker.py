"""A sweep worker: claim a trial, train it, record it, until the study has its trials.

Any number of workers, in any number of processes or machines, run this same loop on one study.
Before each trial a worker fails and re-enqueues trials whose worker died (``storage``). When the
finished and running trials reach the study's count it waits for the running ones (one whose
worker died comes back as a retry) and stops when none is left. Trial numbers come from the
storage, so a trial that would exceed the count (two workers asking at once for the last one)
is told failed at once, as surplus, and trains nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import optuna
from optuna.trial import TrialState

from roto.envs.roto_env import RotoEnv
from roto.jobs.claims import run_claimed, tell_failed
from roto.jobs.storage import fail_stale_trials, reclaim_now, wait_for_running
from roto.sweep.settings import SweepSettings
from roto.sweep.space import load_space
from roto.sweep.study import open_study
from roto.sweep.trial import run_trial

ACTIVE = (TrialState.COMPLETE, TrialState.PRUNED, TrialState.RUNNING)
"""Trials that have their outcome or are being trained: when they reach the count, a worker stops."""
CLAIMED = (*ACTIVE, TrialState.WAITING)
"""Trials that count towards the study's trial count (a waiting one is an enqueued retry; failed ones
do not count)."""


def claimed_before(study: optuna.Study, number: int) -> int:
    """Trials numbered below ``number`` that count towards the study's trial count."""
    return sum(t.number < number for t in study.get_trials(deepcopy=False, states=CLAIMED))


def run_worker(settings: SweepSettings, env_factory: Callable[[Any], Any] = RotoEnv, reclaim: bool = False) -> int:
    """Run trials until the study has ``settings.trials`` and none is running; the number of
    trials this worker finished. ``reclaim``: first fail and retry every running trial
    (``--reclaim-now``)."""
    space = load_space(settings.space, settings.base_env(), settings.agent_cfg, settings.overrides)  # checked first
    study, storage = open_study(settings)
    if reclaim:
        reclaim_now(study, storage)
    finished, told = 0, set()
    while True:
        fail_stale_trials(study, storage, grace=4 * settings.heartbeat)
        if len(study.get_trials(deepcopy=False, states=ACTIVE)) >= settings.trials:
            if wait_for_running(study, settings.heartbeat, told):
                continue
            return finished
        trial = study.ask()
        if claimed_before(study, trial.number) >= settings.trials:
            tell_failed(study, trial, "surplus: the study had its trials")
            return finished

        def work(system_attrs: dict, trial: optuna.Trial = trial) -> float:
            return run_trial(trial, settings, space, system_attrs, env_factory)

        finished += run_claimed(study, storage, trial, settings.heartbeat, work)

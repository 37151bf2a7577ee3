"""The sweep's pruner: the median rule over what earlier trials had reached by the same env steps.

A trial reports its best evaluation so far after each evaluation, at its env steps. Trials that
roll out 16, 32 or 64 steps per update (or evaluate at another interval) report at different env
steps, so Optuna's ``MedianPruner``, which compares only reports at exactly the same step, judged
a trial at most of its evaluations against the few complete trials that happened to share its
grid (often one). Here each complete trial counts with its last report at or before the judged
trial's env steps: the best it had reached by then.
"""

from __future__ import annotations

import statistics

import optuna
from optuna.trial import FrozenTrial, TrialState


def reached_by(trial: FrozenTrial, step: int) -> float | None:
    """``trial``'s last reported value at or before ``step`` (None if it reported none by then)."""
    steps = [s for s in trial.intermediate_values if s <= step]
    return trial.intermediate_values[max(steps)] if steps else None


class MedianBestSoFarPruner(optuna.pruners.BasePruner):
    """Prune a trial whose latest report is below the median of the complete trials' reports by the
    same env steps (as Optuna's median pruner, complete trials only), once ``n_startup_trials``
    trials have completed and the trial has passed ``n_warmup_steps``. Reports are best-so-far
    values of a maximised objective."""

    def __init__(self, n_startup_trials: int, n_warmup_steps: int) -> None:
        if n_startup_trials < 0 or n_warmup_steps < 0:
            raise ValueError(f"n_startup_trials and n_warmup_steps must be >= 0: {n_startup_trials}, {n_warmup_steps}")
        self.n_startup_trials, self.n_warmup_steps = n_startup_trials, n_warmup_steps

    def prune(self, study: optuna.Study, trial: FrozenTrial) -> bool:
        step = trial.last_step
        if step is None or step < self.n_warmup_steps:
            return False
        complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
        if len(complete) < self.n_startup_trials:
            return False
        others = [v for v in (reached_by(t, step) for t in complete) if v is not None]
        return bool(others) and trial.intermediate_values[step] < statistics.median(others)

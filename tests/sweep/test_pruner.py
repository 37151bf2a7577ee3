import optuna
import pytest
from optuna.trial import TrialState

from roto.sweep.pruner import MedianBestSoFarPruner, reached_by


def finished(study, reports, state=TrialState.COMPLETE):
    """Add a finished trial with best-so-far ``reports`` ({env steps: value})."""
    study.add_trial(optuna.trial.create_trial(state=state, value=max(reports.values()) if state == TrialState.COMPLETE
                                              else None, intermediate_values=reports))  # fmt: skip


def judged(study, pruner, reports):
    trial = study.ask()
    for step, value in reports.items():
        trial.report(value, step)
    return pruner.prune(study, study._storage.get_trial(trial._trial_id))


def test_a_trial_is_judged_by_what_the_complete_trials_had_reached_by_its_env_steps():
    study = optuna.create_study(direction="maximize")
    finished(study, {100: 0.0, 200: 50.0, 300: 90.0})  # a grid of 100 env steps (e.g. 64 rollouts)
    finished(study, {100: 0.0, 200: 0.0, 300: 40.0})
    finished(study, {100: 10.0, 200: 20.0, 300: 60.0})
    pruner = MedianBestSoFarPruner(n_startup_trials=3, n_warmup_steps=0)
    # reported at 250 (a 50-step grid): the others by then 50, 0, 20 -> median 20
    assert judged(study, pruner, {150: 5.0, 250: 26.0}) is False
    assert judged(study, pruner, {150: 5.0, 250: 19.0}) is True
    # Optuna's median pruner sees no complete trial at step 250 and cannot judge there at all
    plain = optuna.pruners.MedianPruner(n_startup_trials=3, n_warmup_steps=0)
    assert judged(study, plain, {150: 5.0, 250: 0.0}) is False


def test_nothing_is_pruned_before_the_startup_trials_or_the_warmup_or_any_comparable_report():
    study = optuna.create_study(direction="maximize")
    finished(study, {100: 50.0, 200: 60.0})
    finished(study, {100: 0.0}, state=TrialState.PRUNED)  # pruned trials are not the yardstick
    assert judged(study, MedianBestSoFarPruner(n_startup_trials=2, n_warmup_steps=0), {150: 0.0}) is False
    assert judged(study, MedianBestSoFarPruner(n_startup_trials=1, n_warmup_steps=200), {150: 0.0}) is False
    assert judged(study, MedianBestSoFarPruner(n_startup_trials=1, n_warmup_steps=0), {50: 0.0}) is False
    assert judged(study, MedianBestSoFarPruner(n_startup_trials=1, n_warmup_steps=0), {150: 0.0}) is True


def test_reached_by_takes_the_last_report_at_or_before_the_step():
    trial = optuna.trial.create_trial(state=TrialState.COMPLETE, value=3.0, intermediate_values={10: 1.0, 20: 3.0})
    assert [reached_by(trial, s) for s in (5, 10, 19, 20, 99)] == [None, 1.0, 1.0, 3.0, 3.0]


def test_negative_settings_are_refused_naming_them():
    with pytest.raises(ValueError, match=r"must be >= 0: -1, 0"):
        MedianBestSoFarPruner(n_startup_trials=-1, n_warmup_steps=0)

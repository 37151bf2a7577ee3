"""How a claimed trial's end is told when another worker ended the trial first."""

import optuna
from optuna.trial import TrialState

from roto.jobs.claims import run_claimed
from roto.jobs.storage import open_storage, reclaim_now


def claimed_trial(tmp_path):
    """A study in a journal under ``tmp_path`` with one running trial: (study, storage, trial)."""
    storage = open_storage(tmp_path)
    study = optuna.create_study(study_name="claims", storage=storage, direction="maximize")
    return study, storage, study.ask()


def test_work_that_ends_after_another_worker_reclaimed_its_trial_leaves_the_trial_to_the_retry(tmp_path, capsys):
    """An olympiad cell reports nothing while it trains, so a --reclaim-now run beside it is first
    seen when its outcome is told: the worker says so and goes on, it does not crash."""
    study, storage, trial = claimed_trial(tmp_path)

    def work(system_attrs):
        reclaim_now(study, storage)  # another worker, started with --reclaim-now while this one trains
        return 3.0

    assert run_claimed(study, storage, trial, interval=60.0, work=work) is False
    out = capsys.readouterr().out
    assert f"trial {trial.number}: its work ended here, but another worker had already ended the trial (fail)" in out
    first, retry = study.get_trials(deepcopy=False)
    assert first.state == TrialState.FAIL and retry.state == TrialState.WAITING


def test_work_that_ends_on_a_trial_still_its_own_is_told_complete(tmp_path, capsys):
    study, storage, trial = claimed_trial(tmp_path)
    assert run_claimed(study, storage, trial, interval=60.0, work=lambda attrs: 3.0) is True
    (told,) = study.get_trials(deepcopy=False)
    assert told.state == TrialState.COMPLETE and told.value == 3.0
    assert f"trial {trial.number}: complete, 3.000" in capsys.readouterr().out

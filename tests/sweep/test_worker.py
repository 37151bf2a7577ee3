import json
import multiprocessing
import os
import signal
import time

import optuna
import pytest
import torch
import yaml
from optuna.trial import TrialState

from roto.jobs.storage import REASON_ATTR, open_storage
from roto.rl.config_files import load_agent_config
from roto.rl.evaluation import read_evaluations
from roto.rl.run_dir import CHECKPOINT_DIR
from roto.sweep.report import export_best, show
from roto.sweep.study import SEEDS, open_study
from roto.sweep.trial import run_dir_of
from roto.sweep.worker import run_worker
from tests.rl.toy_env import ToyEnv
from tests.sweep.toy_sweep import TOY_OVERRIDES, toy_settings, toy_worker

FINISHED = (TrialState.COMPLETE, TrialState.PRUNED)


def finished_trials(settings):
    study = optuna.load_study(study_name=settings.study, storage=open_storage(settings.study_dir, settings.storage))
    return study, study.get_trials(states=FINISHED)


def test_a_four_trial_toy_sweep_completes_and_exports_a_loadable_config(tmp_path):
    torch.set_num_threads(1)
    settings = toy_settings(tmp_path, trials=4)
    assert run_worker(settings, env_factory=ToyEnv) == 4
    study, finished = finished_trials(settings)
    assert len(study.trials) == 4 and len(finished) == 4
    for trial in finished:
        run_dir = run_dir_of(settings, trial.number)
        records = read_evaluations(run_dir)  # an ordinary run directory: config, evaluations, checkpoints
        assert (run_dir / "config.yaml").is_file() and (run_dir / CHECKPOINT_DIR / "best.pt").is_file()
        assert trial.user_attrs["seed"] in SEEDS
        if trial.state == TrialState.COMPLETE:
            assert records[-1]["env_steps"] == settings.steps
            assert trial.value == max(r["return_mean"] for r in records)
        # the drawn parameters are the ones the run trained with
        config = yaml.safe_load((run_dir / "config.yaml").read_text())
        assert config["agent"]["ppo"]["lr"] == trial.params["ppo.lr"]
        assert config["agent"]["ppo"]["epochs"] == trial.params["ppo.epochs"]
        assert config["env"]["action_smoothing"] == trial.params["env.action_smoothing"]
        assert config["env"]["seed"] == trial.user_attrs["seed"]

    out = tmp_path / "best.yaml"
    summary = export_best(settings.study, settings.root, None, out)
    agent = load_agent_config("bounce", out)
    best = study.best_trial
    assert summary["trial"] == best.number
    assert agent.ppo.lr == best.params["ppo.lr"] and agent.ppo.epochs == best.params["ppo.epochs"]
    assert agent.network.encoder == (16,) and agent.ppo.rollouts == 4  # the study's fixed overrides too
    assert f"env.action_smoothing={best.params['env.action_smoothing']}" in out.read_text()
    exported = yaml.safe_load(out.read_text())  # a diff: the base, then only what the trial changes
    assert exported["extends"] == "bounce" and "gamma" not in exported["ppo"] and "run" in exported
    assert exported["ppo"]["lr"] == best.params["ppo.lr"] and exported["network"]["encoder"] == [16]
    other = next(t for t in study.get_trials(states=(TrialState.COMPLETE,)) if t.number != best.number)
    export_best(settings.study, settings.root, None, out, other.number)  # a chosen trial instead of the best
    assert load_agent_config("bounce", out).ppo.lr == other.params["ppo.lr"]
    assert f"trial {other.number} (chosen)" in out.read_text()
    with pytest.raises(ValueError, match=r"trial 99 .* is not a complete trial; complete trials: \["):
        export_best(settings.study, settings.root, None, out, 99)

    table = show(settings.study, settings.root, None)
    assert table.count("| complete |") + table.count("| pruned |") == 4
    head, *rows = [line.split(" | ") for line in table.splitlines() if line.startswith("| ")]
    steps = [row[head.index("env steps")] for row in rows]
    assert steps == [str(max(t.intermediate_values)) for t in study.trials]  # where each trial stopped
    assert all(float(row[head.index("minutes")]) >= 0 for row in rows)

    # rerunning the command continues the study up to its count: nothing left to do
    assert run_worker(settings, env_factory=ToyEnv) == 0
    assert len(finished_trials(settings)[0].trials) == 4


@pytest.mark.parametrize("storage", ["journal", "postgresql"])
def test_two_worker_processes_on_one_study_finish_exactly_the_trial_count(tmp_path, storage, request):
    url = request.getfixturevalue("postgres_url") if storage == "postgresql" else None
    settings = toy_settings(tmp_path, trials=6, study=f"toy_two_workers_{storage}", storage=url)
    open_study(settings)
    context = multiprocessing.get_context("spawn")
    workers = [context.Process(target=toy_worker, args=(settings,)) for _ in range(2)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(timeout=300)
        assert worker.exitcode == 0
    study, finished = finished_trials(settings)
    numbers = [t.number for t in finished]
    assert len(finished) == 6 and len(set(numbers)) == 6
    # none lost: every finished trial has its value and its run's evaluations
    for trial in finished:
        assert trial.value is not None and read_evaluations(run_dir_of(settings, trial.number))
    # whatever else is in the study is a surplus claim told failed at once
    others = [t for t in study.trials if t.state not in FINISHED]
    assert all(t.state == TrialState.FAIL and t.user_attrs[REASON_ATTR].startswith("surplus") for t in others)


def test_a_killed_workers_trial_is_failed_and_retried_from_its_checkpoint(tmp_path):
    settings = toy_settings(tmp_path, trials=2, updates=60, heartbeat=0.5)
    open_study(settings)
    worker = multiprocessing.get_context("spawn").Process(target=toy_worker, args=(settings,))
    worker.start()
    first_run = run_dir_of(settings, 0)
    deadline = time.time() + 120
    while len(read_evaluations(first_run)) < 2:  # killed mid-trial, after a few checkpoints
        assert time.time() < deadline and worker.is_alive()
        time.sleep(0.2)
    os.kill(worker.pid, signal.SIGKILL)
    worker.join()
    killed_at = len(read_evaluations(first_run))
    time.sleep(4 * settings.heartbeat + 0.5)  # the grace period passes without a heartbeat

    assert run_worker(settings, env_factory=ToyEnv) == 2
    study = optuna.load_study(study_name=settings.study, storage=open_storage(settings.study_dir))
    first = study.trials[0]
    assert first.state == TrialState.FAIL and "no heartbeat" in first.user_attrs[REASON_ATTR]
    retries = [t for t in study.trials if t.system_attrs.get("failed_trial") == 0]
    assert len(retries) == 1 and retries[0].state in FINISHED
    assert retries[0].params == first.params and retries[0].user_attrs["run_dir"] == str(first_run)
    records = read_evaluations(first_run)
    steps = [r["env_steps"] for r in records]
    assert steps == sorted(set(steps)) and len(records) > killed_at  # resumed, not restarted
    assert len(study.get_trials(states=FINISHED)) == 2
    table = show(settings.study, settings.root, None)
    retry_row = next(line for line in table.splitlines() if line.startswith(f"| {retries[0].number} |"))
    assert "retry of trial 0" in retry_row and "no heartbeat" not in retry_row  # not the first try's reason


class NanRewardToyEnv(ToyEnv):
    """The toy env whose rewards turn NaN after 16 steps: every trial diverges."""

    def step(self, action):
        obs, reward, terminated, truncated, info = super().step(action)
        self.steps = getattr(self, "steps", 0) + 1
        return obs, reward * (float("nan") if self.steps > 16 else 1.0), terminated, truncated, info


def test_diverging_trials_end_pruned_with_the_reason_and_the_study_goes_on(tmp_path):
    settings = toy_settings(tmp_path, trials=3)
    assert run_worker(settings, env_factory=NanRewardToyEnv) == 3
    study, finished = finished_trials(settings)
    assert [t.state for t in study.trials] == [TrialState.PRUNED] * 3
    assert all("non-finite" in t.user_attrs[REASON_ATTR] for t in finished)


def test_a_metric_objective_ranks_trials_by_the_headline_metric_with_the_return_breaking_ties(tmp_path):
    torch.set_num_threads(1)
    settings = toy_settings(tmp_path, trials=2, objective="metric")
    assert run_worker(settings, env_factory=ToyEnv) == 2
    for trial in finished_trials(settings)[1]:
        records = read_evaluations(run_dir_of(settings, trial.number))
        values = [r["hits_mean"] + 1e-6 * r["return_mean"] for r in records]
        assert trial.value == max(values) and trial.intermediate_values[records[-1]["env_steps"]] == max(values)
    from roto.sweep.report import trials_table

    table = trials_table(finished_trials(settings)[0])
    assert "| best eval headline metric (+1e-06 x return) |" in table and f"| {trial.value:.6f} |" in table
    with pytest.raises(ValueError, match=r"'objective': \('metric', 'return'\)"):
        open_study(toy_settings(tmp_path, trials=2))  # the stored objective is part of the study
    refusal = r"unknown objective 'rotations' for task 'bounce'; valid objectives: \['return', 'metric', 'bounces'\]"
    with pytest.raises(ValueError, match=refusal):
        toy_settings(tmp_path, trials=2, objective="rotations")


def test_an_objective_may_name_another_metric_of_the_task_with_the_return_breaking_ties():
    from roto.sweep.report import _objective_name
    from roto.sweep.settings import SweepSettings, objectives_of
    from roto.sweep.trial import objective_value

    assert objectives_of("baoding")[-1] == "round_rotations"
    settings = SweepSettings(study="round", task="baoding", objective="round_rotations")
    swing = {"return_mean": 400.0, "rotations_mean": 13.27, "round_rotations_mean": 0.26}
    round_ = {"return_mean": 300.0, "rotations_mean": 11.22, "round_rotations_mean": 11.22}
    assert objective_value(swing, "metric", "rotations") > objective_value(round_, "metric", "rotations")
    assert objective_value(swing, settings.objective, "rotations") == 0.26 + 1e-6 * 400.0
    assert objective_value(round_, settings.objective, "rotations") == 11.22 + 1e-6 * 300.0
    assert _objective_name(settings.identity()) == "round_rotations (+1e-06 x return)"


def test_a_study_stored_before_objectives_existed_is_joined_as_a_return_study(tmp_path):
    from roto.sweep.study import SETTINGS_ATTR

    settings = toy_settings(tmp_path, trials=2)
    study, _ = open_study(settings)
    old = {k: v for k, v in settings.identity().items() if k != "objective"}
    study.set_user_attr(SETTINGS_ATTR, old)
    open_study(settings)  # joins
    with pytest.raises(ValueError, match=r"'objective': \('return', 'metric'\)"):
        open_study(toy_settings(tmp_path, trials=2, objective="metric"))


def test_the_base_config_is_enqueued_as_the_first_trial_where_the_space_can_draw_it(tmp_path):
    from roto.sweep.space import load_space
    from roto.sweep.study import enqueue_base

    torch.set_num_threads(1)
    settings = toy_settings(tmp_path, trials=2, overrides=(*TOY_OVERRIDES, "env.action_smoothing=0.5"))
    study, _ = open_study(settings)
    space = load_space(settings.space, settings.base_env(), settings.agent_cfg, settings.overrides)
    inside, outside = enqueue_base(study, settings, space)
    base = load_agent_config("bounce")
    assert inside == {"ppo.lr": base.ppo.lr, "env.action_smoothing": 0.5}  # the study's fixed override counts
    assert outside == {"ppo.epochs": 17}  # roto's 17 epochs: outside the toy space's 1-3, drawn instead
    assert run_worker(settings, env_factory=ToyEnv) == 2
    first = finished_trials(settings)[0].trials[0]
    assert first.params["ppo.lr"] == base.ppo.lr and first.params["env.action_smoothing"] == 0.5
    assert 1 <= first.params["ppo.epochs"] <= 3
    with pytest.raises(ValueError, match=r"already has 2 trials; the base run is enqueued only as a new study"):
        enqueue_base(study, settings, space)


def test_the_enqueued_base_has_the_training_aids_of_its_agent_config(tmp_path):
    from roto.sweep.settings import SweepSettings
    from roto.sweep.space import load_space
    from roto.sweep.study import enqueue_base

    settings = SweepSettings(study="aids", task="baoding", agent_cfg="baoding_cpu", space="baoding_cpu",
                             objective="metric", trials=2, num_envs=8, root=str(tmp_path))  # fmt: skip
    study, _ = open_study(settings)
    space = load_space(settings.space, settings.base_env(), settings.agent_cfg, settings.overrides)
    inside, _ = enqueue_base(study, settings, space)
    assert inside["env.aids.replayed_starts.share"] == 0.5 and inside["ppo.epochs"] == 4  # baoding_cpu's, not defaults


def test_joining_a_study_with_other_settings_is_an_error(tmp_path):
    open_study(toy_settings(tmp_path, trials=4))
    with pytest.raises(ValueError, match=r"exists with other settings.*'steps': \(192, 320\)"):
        open_study(toy_settings(tmp_path, trials=4, updates=10))
    open_study(toy_settings(tmp_path, trials=6))  # a larger trial count extends the study


def test_rerunning_with_a_larger_count_extends_the_study(tmp_path):
    assert run_worker(toy_settings(tmp_path, trials=2), env_factory=ToyEnv) == 2
    assert run_worker(toy_settings(tmp_path, trials=3), env_factory=ToyEnv) == 1
    assert len(finished_trials(toy_settings(tmp_path, trials=3))[1]) == 3


def test_cli_sweep_needs_a_study_and_show_names_missing_ones(tmp_path, capsys):
    from roto.cli import main

    assert main(["sweep", "--trials", "2"]) == 2
    assert "--study is required" in capsys.readouterr().err
    assert main(["sweep", "show", "--study", "nope", "--root", str(tmp_path)]) == 2
    assert "no study 'nope'" in capsys.readouterr().err
    settings = toy_settings(tmp_path, trials=1)
    run_worker(settings, env_factory=ToyEnv)
    capsys.readouterr()
    assert main(["sweep", "export", "--study", "toy", "--root", str(tmp_path), "--out", str(tmp_path / "b.yaml")]) == 0
    assert json.loads(capsys.readouterr().out)["trial"] == 0


def test_cli_workers_run_a_study_on_the_real_env_and_show_it(tmp_path, capsys):
    from roto.cli import main

    space = toy_settings(tmp_path, trials=2).space  # writes the toy space file
    fixed = [arg for override in TOY_OVERRIDES for arg in ("--set", override)]
    args = ["sweep", "--study", "cli", "--root", str(tmp_path), "--space", space, "--trials", "2", "--startup", "1",
            "--steps", "16", "--num_envs", "2", "--workers", "2", *fixed]  # fmt: skip
    assert main(args) == 0
    study = optuna.load_study(study_name="cli", storage=open_storage(tmp_path / "cli"))
    assert len(study.get_trials(states=FINISHED)) == 2
    capsys.readouterr()
    assert main(["sweep", "show", "--study", "cli", "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    head = "| trial | state | best eval return | seed | env steps | minutes | env.action_smoothing | ppo.epochs |"
    assert head in out and "| ppo.lr | reason |" in out


def test_the_command_that_enqueued_the_base_continues_its_study_without_enqueueing_it_again(tmp_path, capsys):
    from roto.cli import main

    space = toy_settings(tmp_path, trials=2).space  # writes the toy space file
    fixed = [arg for override in TOY_OVERRIDES for arg in ("--set", override)]
    args = ["sweep", "--study", "again", "--root", str(tmp_path), "--space", space, "--startup", "1",
            "--steps", "16", "--num_envs", "2", "--enqueue_base", *fixed]  # fmt: skip
    assert main([*args, "--trials", "1"]) == 0
    assert "enqueued the base config as the first trial" in capsys.readouterr().err
    assert main([*args, "--trials", "2"]) == 0  # a rerun (a new sitting) with the same flags
    assert "already has 1 trials, so the base config" in capsys.readouterr().err
    trials = optuna.load_study(study_name="again", storage=open_storage(tmp_path / "again")).get_trials()
    assert [t.state for t in trials] == [TrialState.COMPLETE, TrialState.COMPLETE]
    assert trials[0].params["ppo.lr"] == load_agent_config("bounce").ppo.lr  # the base, once
    assert trials[1].params["ppo.lr"] != trials[0].params["ppo.lr"]  # drawn, not the base again


def test_a_bad_space_with_several_workers_is_refused_before_the_study_exists(tmp_path, capsys):
    from roto.cli import main

    space = tmp_path / "bad_space.yaml"
    space.write_text("ppo:\n  no_such_key: {low: 1, high: 2}\n")
    args = [
        "sweep",
        "--study",
        "bad",
        "--root",
        str(tmp_path),
        "--space",
        str(space),
        "--trials",
        "2",
        "--workers",
        "2",
    ]
    assert main(args) == 2
    assert "unknown sections ['ppo']" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()  # no study folder, no journal

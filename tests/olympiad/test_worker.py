import json
import multiprocessing
import os
import signal
import time

import optuna
import torch
import yaml
from optuna.trial import TrialState

from roto.jobs.storage import REASON_ATTR, open_storage
from roto.olympiad.plan import load_plan
from roto.olympiad.worker import CELL_ATTR, cell_status, study_name
from roto.rl.checkpoints import load_checkpoint
from roto.rl.evaluation import read_evaluations
from tests.olympiad.toy_plan import toy_worker, write_toy_plan


def load_study(root, plan):
    return optuna.load_study(study_name=study_name(plan), storage=open_storage(root / plan.name))


def signal_worker_after_two_evaluations(plan_path, root, heartbeat, first_cell_dir, signum):
    """Start a toy worker process, send it ``signum`` once its first cell has two evaluations; its exit code."""
    worker = multiprocessing.get_context("spawn").Process(target=toy_worker, args=(plan_path, root, heartbeat))
    worker.start()
    deadline = time.time() + 120
    while len(read_evaluations(first_cell_dir)) < 2:
        assert time.time() < deadline and worker.is_alive()
        time.sleep(0.2)
    os.kill(worker.pid, signum)
    worker.join(timeout=60)
    return worker.exitcode


def test_two_workers_finish_every_cell_once(tmp_path):
    plan_path = write_toy_plan(tmp_path)
    plan, root = load_plan(str(plan_path)), tmp_path / "runs"
    assert len(plan.cells) == 8  # 2 tasks x 2 robots x 1 obs x 1 variant x 2 seeds
    context = multiprocessing.get_context("spawn")
    workers = [context.Process(target=toy_worker, args=(plan_path, root)) for _ in range(2)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(timeout=300)
        assert worker.exitcode == 0
    study = load_study(root, plan)
    complete = [t.user_attrs[CELL_ATTR] for t in study.get_trials(states=(TrialState.COMPLETE,))]
    assert sorted(complete) == sorted(c.name for c in plan.cells)  # every cell once, none twice
    others = [t for t in study.trials if t.state != TrialState.COMPLETE]
    assert all(t.user_attrs[REASON_ATTR].startswith("duplicate") for t in others)
    results = root / plan.name / "results"
    for cell in plan.cells:
        summary = json.loads((results / f"{cell.name}.json").read_text())
        assert summary["env_steps"] == plan.steps and summary["seed"] == cell.seed
        assert summary["final"]["episodes"] == plan.eval_episodes == len(summary["best"]["per_episode"]["return"])
        assert summary["evaluations"] == [
            {k: v for k, v in r.items() if k != "per_episode"} for r in read_evaluations(root / plan.name / cell.name)
        ]
        assert [row["env_steps"] for row in summary["training"]] == [r["env_steps"] for r in summary["evaluations"]]
        assert all(row["ppo/action_std"] > 0 for row in summary["training"])
    assert set(cell_status(plan, str(root), results, None).values()) == {"done"}
    # rerunning skips finished cells, with the journal or (another sitting) from the summaries alone
    assert toy_worker(plan_path, root) == 0
    (root / plan.name / "journal.log").unlink()
    assert toy_worker(plan_path, root) == 0


def test_a_killed_workers_cell_is_resumed_from_its_checkpoint(tmp_path):
    plan_path = write_toy_plan(tmp_path, updates=60, seeds=(0,))
    plan, root = load_plan(str(plan_path)), tmp_path / "runs"
    first = root / plan.name / plan.cells[0].name
    signal_worker_after_two_evaluations(plan_path, root, 0.5, first, signal.SIGKILL)
    killed_at = len(read_evaluations(first))
    time.sleep(2.5)  # four missed heartbeats

    assert toy_worker(plan_path, root, 0.5) == len(plan.cells)
    study = load_study(root, plan)
    dead = study.trials[0]
    assert dead.state == TrialState.FAIL and "no heartbeat" in dead.user_attrs[REASON_ATTR]
    retry = [t for t in study.trials if t.system_attrs.get("failed_trial") == dead.number]
    assert len(retry) == 1 and retry[0].state == TrialState.COMPLETE
    assert retry[0].user_attrs[CELL_ATTR] == dead.user_attrs[CELL_ATTR] == plan.cells[0].name
    fresh = [t for t in study.trials if t.state == TrialState.COMPLETE and t.number != retry[0].number]
    assert len(fresh) == len(plan.cells) - 1 and retry[0].number > max(t.number for t in fresh)
    assert all(retry[0].datetime_start < t.datetime_start for t in fresh)  # the interrupted cell finishes first
    steps = [r["env_steps"] for r in read_evaluations(first)]
    assert steps == sorted(set(steps)) and len(steps) > killed_at and steps[-1] == plan.steps  # resumed


def test_a_sigterm_fails_the_workers_cell_at_once_and_its_retry_continues_from_the_stop(tmp_path):
    """kill (or a scheduler's preemption): the cell's update finishes and is saved, its trial is failed
    and re-enqueued before the worker exits, so the next worker resumes it without waiting for
    missed heartbeats."""
    plan_path = write_toy_plan(tmp_path, updates=60, seeds=(0,))
    plan, root = load_plan(str(plan_path)), tmp_path / "runs"
    first = root / plan.name / plan.cells[0].name
    exitcode = signal_worker_after_two_evaluations(plan_path, root, 60.0, first, signal.SIGTERM)
    assert exitcode not in (0, None, -signal.SIGTERM)  # it stopped itself, through its clean-up
    (stopped,) = load_study(root, plan).trials[:1]
    assert stopped.state == TrialState.FAIL and "SIGTERM: stopped after update" in stopped.user_attrs[REASON_ATTR]
    stopped_at = len(read_evaluations(first))

    start = time.time()
    assert toy_worker(plan_path, root, 60.0) == len(plan.cells)
    assert time.time() - start < 60  # no stale heartbeat to wait for (they beat every 60 s here)
    retry = [t for t in load_study(root, plan).trials if t.system_attrs.get("failed_trial") == stopped.number]
    assert len(retry) == 1 and retry[0].state == TrialState.COMPLETE
    steps = [r["env_steps"] for r in read_evaluations(first)]
    assert steps == sorted(set(steps)) and len(steps) > stopped_at and steps[-1] == plan.steps  # resumed


def test_started_cells_are_claimed_before_fresh_cells_the_most_trained_first_without_being_retries(tmp_path):
    """A cell reclaimed at the end of more sittings than Optuna retries (3) is enqueued afresh, at the
    back of the queue; its checkpoint still puts it first, and of two the one nearer its end."""
    from roto.olympiad.cell import cell_spec
    from roto.rl.runner import Trainer
    from tests.rl.toy_env import ToyEnv

    root = tmp_path / "runs"
    for updates, index in ((2, -2), (4, -1)):  # sittings that trained only the plan's last two cells
        plan = load_plan(str(write_toy_plan(tmp_path, updates=updates, seeds=(0,))))
        Trainer.open(root / plan.name / plan.cells[index].name, cell_spec(plan, plan.cells[index]),
                     env_factory=ToyEnv).train(progress=False)  # fmt: skip
    plan_path = write_toy_plan(tmp_path, updates=6, seeds=(0,))  # a longer budget: every cell has work left

    assert toy_worker(plan_path, root) == len(plan.cells)
    trials = sorted(load_study(root, plan).trials, key=lambda t: t.datetime_start)
    assert all(t.state == TrialState.COMPLETE and "failed_trial" not in t.system_attrs for t in trials)
    assert [t.user_attrs[CELL_ATTR] for t in trials[:2]] == [plan.cells[-1].name, plan.cells[-2].name]
    assert [t.number for t in trials[:2]] == [len(plan.cells) - 1, len(plan.cells) - 2]  # enqueued last, claimed first
    for cell in plan.cells[-2:]:
        steps = [r["env_steps"] for r in read_evaluations(root / plan.name / cell.name)]
        assert steps == sorted(set(steps)) and steps[-1] == 8 * 4 * 6  # continued, not restarted


def test_a_finished_cell_whose_summary_is_taken_away_continues_to_the_plans_longer_budget(tmp_path):
    """The way to give finished cells more env steps: a longer budget in the plan, their summaries
    moved aside; their runs continue where they stopped, and cells that keep a summary stay done."""
    root = tmp_path / "runs"
    plan = load_plan(str(write_toy_plan(tmp_path, updates=2, seeds=(0,))))
    assert toy_worker(tmp_path / "toy.yaml", root) == len(plan.cells)
    results, longer = root / plan.name / "results", plan.cells[0]
    (results / f"{longer.name}.json").unlink()
    plan = load_plan(str(write_toy_plan(tmp_path, updates=4, seeds=(0,))))
    assert cell_status(plan, str(root), results, None)[longer.name] == "not started"

    assert toy_worker(tmp_path / "toy.yaml", root) == 1
    steps = [r["env_steps"] for r in read_evaluations(root / plan.name / longer.name)]
    assert steps == sorted(set(steps)) and steps[-1] == 8 * 4 * 4  # continued from 2 updates, not restarted
    assert json.loads((results / f"{longer.name}.json").read_text())["env_steps"] == 8 * 4 * 4
    for cell in plan.cells[1:]:
        assert json.loads((results / f"{cell.name}.json").read_text())["env_steps"] == 8 * 4 * 2
    assert set(cell_status(plan, str(root), results, None).values()) == {"done"}


def test_a_summary_names_each_commit_that_trained_its_cell_and_where_each_started(tmp_path):
    """A cell resumed by code of another commit: both commits and the env steps each took over at;
    a start that only evaluates (its budget spent) trains nothing and adds none."""
    from roto.olympiad.cell import run_cell
    from roto.olympiad.results import page_label
    from tests.rl.toy_env import ToyEnv

    results = tmp_path / "results"
    plan = load_plan(str(write_toy_plan(tmp_path, updates=2, seeds=(0,))))
    cell, run_dir = plan.cells[0], tmp_path / "runs" / plan.cells[0].name
    run_cell(plan, cell, run_dir, results, "aaa1111", ToyEnv)
    plan = load_plan(str(write_toy_plan(tmp_path, updates=4, seeds=(0,))))
    run_cell(plan, cell, run_dir, results, "bbb2222", ToyEnv)
    summary = run_cell(plan, cell, run_dir, results, "ccc3333", ToyEnv)

    starts = [{"commit": "aaa1111", "from_env_steps": 0}, {"commit": "bbb2222", "from_env_steps": 8 * 4 * 2}]
    assert summary["trained_by"] == starts and summary["commit"] == "ccc3333"
    assert json.loads((results / f"{cell.name}.json").read_text())["trained_by"] == starts
    assert page_label([summary]) == "plan toy, commit aaa1111, bbb2222, ccc3333"


def test_a_summarys_best_update_is_the_update_best_pt_holds(tmp_path):
    """Not the evaluation with the best return: Baoding chooses best.pt by round rotations."""
    root = tmp_path / "runs"
    plan = load_plan(str(write_toy_plan(tmp_path, updates=4, seeds=(0,))))
    assert toy_worker(tmp_path / "toy.yaml", root) == len(plan.cells)
    cell = plan.cells[0]
    best_path = root / plan.name / cell.name / "checkpoints" / "best.pt"
    best_pt = load_checkpoint(best_path)
    records = read_evaluations(root / plan.name / cell.name)
    other = next(r["update"] for r in records if r["update"] != best_pt["update"])
    torch.save({**best_pt, "update": other}, best_path)  # as if another evaluation had been chosen
    (root / plan.name / "results" / f"{cell.name}.json").unlink()
    assert toy_worker(tmp_path / "toy.yaml", root) == 1
    assert json.loads((root / plan.name / "results" / f"{cell.name}.json").read_text())["best_update"] == other


def test_a_waiting_cell_no_longer_in_the_plan_is_failed_with_its_name(tmp_path):
    plan_path = write_toy_plan(tmp_path, seeds=(0,))
    plan, root = load_plan(str(plan_path)), tmp_path / "runs"
    results = root / plan.name / "results"
    results.mkdir(parents=True)
    for cell in plan.cells:  # every cell of the plan is done; a cell of an older plan still waits
        (results / f"{cell.name}.json").write_text("{}")
    study = optuna.create_study(study_name=study_name(plan), storage=open_storage(root / plan.name))
    study.enqueue_trial({}, user_attrs={CELL_ATTR: "bounce-ghost-blind-ppo-seed0"})

    assert toy_worker(plan_path, root) == 0
    (ghost,) = load_study(root, plan).trials
    assert ghost.state == TrialState.FAIL
    assert ghost.user_attrs[REASON_ATTR] == "unknown cell 'bounce-ghost-blind-ppo-seed0': not in plan 'toy'"


def test_a_worker_with_only_trains_only_its_cells_and_leaves_the_others_waiting_for_any_worker(tmp_path):
    from roto.olympiad.worker import run_olympiad_worker
    from tests.rl.toy_env import ToyEnv

    plan_path = write_toy_plan(tmp_path, seeds=(0,))
    plan, root = load_plan(str(plan_path)), tmp_path / "runs"
    results = root / plan.name / "results"
    study = optuna.create_study(study_name=study_name(plan), storage=open_storage(root / plan.name))
    other = next(c.name for c in plan.cells if c.task == "baoding")
    study.enqueue_trial({}, user_attrs={CELL_ATTR: other})  # queued by a worker without --only
    assert run_olympiad_worker(plan, str(root), heartbeat=5.0, env_factory=ToyEnv, only=["bounce-*"]) == 2
    trials = load_study(root, plan).trials
    done = sorted(t.user_attrs[CELL_ATTR] for t in trials if t.state == TrialState.COMPLETE)
    assert done == sorted(c.name for c in plan.cells if c.task == "bounce")
    assert [t.user_attrs[CELL_ATTR] for t in trials if t.state == TrialState.WAITING] == [other]
    assert sorted(p.stem for p in results.glob("*.json")) == done
    assert run_olympiad_worker(plan, str(root), heartbeat=5.0, env_factory=ToyEnv) == 2  # the baoding cells
    assert set(cell_status(plan, str(root), results, None).values()) == {"done"}


def test_a_worker_waits_only_for_the_running_trials_it_watches():
    from roto.jobs.storage import wait_for_running

    study = optuna.create_study()
    trial = study.ask()  # running, as a cell another worker trains
    told = set()
    assert not wait_for_running(study, 0.01, told, lambda t: False) and not told
    assert wait_for_running(study, 0.01, told) and told == {(trial.number,)}


def test_cli_olympiad_with_two_workers_on_the_real_env_then_results(tmp_path, capsys):
    from roto.cli import main
    from tests.olympiad.toy_plan import TINY

    plan_path = tmp_path / "real.yaml"
    tiny = "[" + ", ".join(f"'{o}'" for o in TINY) + "]"
    plan_path.write_text(
        f"steps: 16\neval_episodes: 2\nnum_envs: 2\nvariants:\n  ppo:\n    bounce: {{overrides: {tiny}}}\n"
        "grids:\n  - {tasks: [bounce], robots: [shadow, allegro], obs: [blind], variants: [ppo], seeds: [0]}\n"
    )
    root = tmp_path / "runs"
    assert main(["olympiad", str(plan_path), "--root", str(root), "--workers", "2", "--threads", "2"]) == 0
    study = load_study(root, load_plan(str(plan_path)))
    assert len(study.get_trials(states=(TrialState.COMPLETE,))) == 2
    # the command enqueued the cells before starting its workers: none was enqueued twice
    assert not any("duplicate" in t.user_attrs.get(REASON_ATTR, "") for t in study.trials)
    results = root / "real" / "results"
    assert sorted(p.name for p in results.glob("*.json")) == [
        "bounce-allegro-blind-ppo-seed0.json", "bounce-shadow-blind-ppo-seed0.json"
    ]  # fmt: skip
    summary = json.loads((results / "bounce-shadow-blind-ppo-seed0.json").read_text())
    assert summary["final"]["episodes"] == 2 and "bounces_mean" in summary["best"]
    assert main(["results", str(plan_path), "--root", str(root), "--out", str(tmp_path / "out")]) == 0
    assert "| allegro | " in (tmp_path / "out" / "results.md").read_text()
    for cell in ("bounce-shadow-blind-ppo-seed0", "bounce-allegro-blind-ppo-seed0"):  # the plan's default is 1
        assert yaml.safe_load((root / "real" / cell / "config.yaml").read_text())["env"]["threads"] == 2


def test_cli_olympiad_refuses_a_thread_count_below_one_by_value(tmp_path, capsys):
    from roto.cli import main

    assert main(["olympiad", "benchmark", "--root", str(tmp_path), "--threads", "0"]) == 2
    assert "--threads must be >= 1, got 0" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())

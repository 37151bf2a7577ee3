"""One Olympiad cell: train its run, evaluate its final and best policies, write its summary.

The run directory is ``<root>/<plan>/<cell>`` (an ordinary run: ``roto eval``, ``roto play`` and
``roto train --resume`` work on it); a cell whose run has a checkpoint continues from it. The
summary, ``<results>/<cell>.json``, is small enough to commit: the evaluation curve, the training
scalars between evaluations (the policy's action std, the training episodes' return, length and
task metrics), the training aids its run used and its whole run spec, the final and best
policies' evaluations over the plan's episodes (per-episode returns and task metrics included),
the training wall time, the commit that wrote it and the commits that trained it: each start of
training appends its commit and the env steps it started from to ``<run_dir>/commits.jsonl``
(``TRAINED_BY``), so a cell resumed across commits names each. ``roto results`` reads only
summaries, so cells trained on other machines or in other sittings combine.
"""

from __future__ import annotations

import bisect
import copy
import json
import pathlib
import subprocess
from collections.abc import Callable
from typing import Any

import roto
from roto.artifact_formats import format_stamp
from roto.envs.config import EnvConfig
from roto.envs.roto_env import RotoEnv
from roto.eval.evaluate import evaluate
from roto.olympiad.plan import Cell, Plan
from roto.result_files import write_text_atomic
from roto.rl.checkpoints import load_checkpoint
from roto.rl.evaluation import read_evaluations
from roto.rl.run_dir import RunDir, read_scalars
from roto.rl.run_lock import wait_until_free
from roto.rl.run_spec import RunSpec, build_run_spec
from roto.rl.runner import Trainer
from roto.tasks import get_task


def code_commit() -> str:
    """The commit (short hash) of the roto code that runs: that of the git checkout holding the ``roto``
    package, whatever the current directory; "unknown" when the package is not a tracked part of a git
    checkout (an installed copy, even one inside another project's checkout) or git is missing."""
    package = pathlib.Path(roto.__file__).resolve().parent

    def git(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run(["git", "-C", str(package), *args], capture_output=True, text=True, check=False)

    try:
        tracked = git("ls-files", "--error-unmatch", "__init__.py").returncode == 0
        out = git("rev-parse", "--short", "HEAD") if tracked else None
    except OSError:  # no git on this machine
        return "unknown"
    return out.stdout.strip() if out is not None and out.returncode == 0 and out.stdout.strip() else "unknown"


TRAINED_BY = "commits.jsonl"
"""A run directory's record of the commits that trained it: one JSON line per start of training."""


def record_training_start(run_dir: pathlib.Path, commit: str, from_env_steps: int) -> None:
    """Append ``{"commit", "from_env_steps"}`` to the run's ``TRAINED_BY`` (a start that trains)."""
    with (run_dir / TRAINED_BY).open("a") as f:
        f.write(json.dumps({"commit": commit, "from_env_steps": from_env_steps}) + "\n")


def trained_by(run_dir: pathlib.Path) -> list[dict[str, Any]]:
    """The run's training starts, oldest first ([] where none was recorded: a run trained before
    roto kept the record, or outside a plan); a run whose first start is above 0 env steps was
    trained before that by code the record does not name."""
    path = run_dir / TRAINED_BY
    return [json.loads(line) for line in path.read_text().splitlines() if line] if path.is_file() else []


TRAINING_SCALARS = ("ppo/action_std",)  # besides every ``train/...`` scalar (the training episodes')


def training_curve(scalars: dict[str, tuple[list[int], list[float]]], env_steps: list[int]) -> list[dict[str, float]]:
    """For each of ``env_steps`` (ascending: the evaluations'), the mean of the policy's action std
    and of every ``train/...`` scalar over the updates logged after the previous one and up to it
    (a tag with no update there is left out). ``scalars``: {tag: (env_steps, values)}, ascending."""
    tags = sorted(tag for tag in scalars if tag in TRAINING_SCALARS or tag.startswith("train/"))
    rows, previous = [], -1
    for step in env_steps:
        row: dict[str, float] = {"env_steps": step}
        for tag in tags:
            steps, values = scalars[tag]
            window = values[bisect.bisect_right(steps, previous) : bisect.bisect_right(steps, step)]
            if window:
                row[tag] = sum(window) / len(window)
        rows.append(row)
        previous = step
    return rows


def summary_path(results: pathlib.Path, cell: Cell) -> pathlib.Path:
    """Where a finished cell's summary is."""
    return results / f"{cell.name}.json"


def cell_spec(plan: Plan, cell: Cell) -> RunSpec:
    """What a cell trains: the plan's envs, the cell's budget (``Plan.steps_for``), the variant's
    agent and env overrides for the task, the cell's seed (which wins over any ``env.seed`` override)."""
    agent_cfg, overrides = plan.variants[cell.variant].agent_for(cell.task, cell.robot)
    spec = build_run_spec(
        cell.task,
        cell.robot,
        cell.obs,
        agent_cfg,
        overrides,
        plan.steps_for(cell),
        num_envs=plan.num_envs,
        threads=plan.threads,
        backend=plan.backend,
        device=plan.device,
    )
    return spec.with_seed(cell.seed)


def agent_record(plan: Plan, cell: Cell) -> dict[str, Any]:
    """A summary's ``agent``: the label of the config the plan trains the cell with, and the roto
    agent its variant declares itself to be (None)."""
    entry = plan.variants[cell.variant].for_task(cell.task)
    return {"label": entry.label, "roto_agent": entry.roto_agent}


def run_cell(
    plan: Plan,
    cell: Cell,
    run_dir: pathlib.Path,
    results: pathlib.Path,
    commit: str,
    env_factory: Callable[[EnvConfig], Any] = RotoEnv,
) -> dict[str, Any]:
    """Train (or continue) the cell, evaluate it, write and return its summary."""
    wait_until_free(run_dir)  # a retry of a cell whose first worker, declared dead, is still training it
    with Trainer.open(run_dir, cell_spec(plan, cell), env_factory=env_factory) as trainer:
        if not trainer.finished:
            record_training_start(run_dir, commit, trainer.env_steps)
        trainer.train(progress=False)
    final = copy.deepcopy(trainer.model).cpu().eval()
    best = copy.deepcopy(final)
    best_checkpoint = load_checkpoint(RunDir(run_dir).checkpoint("best"))
    best.load_state_dict(best_checkpoint["model"])
    records = read_evaluations(run_dir)
    summary = {
        **format_stamp("cell summary"),
        **{key: getattr(cell, key) for key in ("task", "robot", "obs", "variant", "seed")},
        "task_version": get_task(cell.task).version,
        "plan": plan.name,
        "agent": agent_record(plan, cell),
        "training_aids": trainer.spec.env.aids.to_dict(),
        "spec": trainer.spec.to_dict(),  # what the plan check compares (roto.olympiad.staleness)
        "commit": commit,
        "trained_by": trained_by(run_dir),
        "run_dir": str(run_dir),
        "env_steps": trainer.env_steps,
        "train_wall_s": trainer.train_seconds,
        "best_update": best_checkpoint["update"],  # chosen by the task's selection metric, as best.pt
        "evaluations": [{k: v for k, v in r.items() if k != "per_episode"} for r in records],
        "training": training_curve(read_scalars(run_dir), [r["env_steps"] for r in records]),
        "final": evaluate(final, trainer.spec, plan.eval_episodes, env_factory=env_factory),
        "best": evaluate(best, trainer.spec, plan.eval_episodes, env_factory=env_factory),
    }
    results.mkdir(parents=True, exist_ok=True)
    write_text_atomic(summary_path(results, cell), json.dumps(summary, indent=1))
    return summary

"""``roto sweep export`` (the best trial as an agent config) and ``roto sweep show`` (trials, importances)."""

from __future__ import annotations

import os
import pathlib

import optuna
import yaml
from optuna.trial import TrialState

from roto.jobs.storage import REASON_ATTR, RETRY_OF_ATTR
from roto.result_files import write_text_atomic
from roto.rl.config import to_dict
from roto.rl.config_files import load_agent_config, packaged_configs
from roto.rl.overrides import split_overrides
from roto.sweep.space import as_overrides
from roto.sweep.study import SETTINGS_ATTR, TIE_BREAK, load_existing_study


def export_best(
    name: str, root: str, storage_url: str | None, out: str | pathlib.Path, number: int | None = None
) -> dict:
    """Write the best complete trial's agent config (or trial ``number``'s, a complete one) to ``out``
    (YAML ``roto train --agent_cfg`` loads), as a diff: ``extends:`` the study's base config, then
    only what the trial changes (the searched values and the study's fixed agent overrides).

    Env parameters of the trial (``env.*``) are not agent settings: the file's header gives the
    ``roto train`` command with them. Returns a summary of the trial.
    """
    study, settings = load_existing_study(name, root, storage_url)
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    if not complete:
        raise ValueError(f"study {name!r} has no complete trial yet; nothing to export")
    if number is None:
        best = study.best_trial
    else:
        best = next((t for t in complete if t.number == number), None)
        if best is None:
            choices = [t.number for t in complete]
            raise ValueError(f"trial {number} of study {name!r} is not a complete trial; complete trials: {choices}")
    env_changes, agent_overrides = split_overrides([*settings["overrides"], *as_overrides(best.params)])
    agent = load_agent_config(settings["task"], settings["agent_cfg"], agent_overrides)
    env_args = " ".join(f"env.{k}={v}" for k, v in env_changes.items())
    header = [
        f"# roto sweep export: study {name!r}, trial {best.number}"
        f" ({'the best' if best.number == study.best_trial.number else 'chosen'}),"
        f" best evaluation {_objective_name(settings)} {best.value:.6g}"
        f" (seed {best.user_attrs.get('seed')}, {settings['steps']} env steps)",
        f"# base config: {settings['agent_cfg'] or settings['task'] + ' (default)'}; search space: {settings['space']}",
        f"# train with: roto train --task {settings['task']} --robot {settings['robot']} --obs {settings['obs']}"
        f" --num_envs {settings['num_envs']} --agent_cfg {out} {env_args}".rstrip(),
    ]
    path = pathlib.Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    base = settings["agent_cfg"] or settings["task"]
    changes = changed_keys(to_dict(load_agent_config(settings["task"], settings["agent_cfg"])), to_dict(agent))
    body = {"extends": extends_name(base, path), **changes}  # the trial as a diff from the study's base config
    write_text_atomic(path, "\n".join(header) + "\n" + yaml.safe_dump(body, sort_keys=False))
    return {"study": name, "trial": best.number, "value": best.value, "params": best.params, "out": str(path)}


def changed_keys(base: dict, config: dict) -> dict:
    """The parts of nested dict ``config`` that differ from ``base`` (sections kept only where
    something in them changed)."""
    changes = {}
    for key, value in config.items():
        if isinstance(value, dict) and isinstance(base.get(key), dict):
            inner = changed_keys(base[key], value)
            if inner:
                changes[key] = inner
        elif base.get(key, object()) != value:
            changes[key] = value
    return changes


def extends_name(base: str, out: pathlib.Path) -> str:
    """How a config written to ``out`` names its base: a packaged name as it is, a file by its
    path relative to ``out``'s folder."""
    if base in packaged_configs():
        return base
    return os.path.relpath(pathlib.Path(base).resolve(), out.resolve().parent)


def trials_table(study: optuna.Study) -> str:
    """A markdown table of every trial: number, state, objective, seed, the env steps of its last
    report, its wall minutes (of its last attempt), parameters, why it ended."""
    trials = study.get_trials(deepcopy=False)
    keys = sorted({k for t in trials for k in t.params})
    settings = study.user_attrs.get(SETTINGS_ATTR, {})
    by_metric = _objective_name(settings) != "return"  # the metric's steps are small: more digits
    head = ["trial", "state", f"best eval {_objective_name(settings)}", "seed", "env steps", "minutes", *keys, "reason"]
    rows = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for t in trials:
        value = (f"{t.value:.6f}" if by_metric else f"{t.value:.3f}") if t.value is not None else ""
        steps = str(max(t.intermediate_values)) if t.intermediate_values else ""
        params = [_short(t.params[k]) if k in t.params else "" for k in keys]
        cells = [str(t.number), t.state.name.lower(), value, str(t.user_attrs.get("seed", "")), steps, _minutes(t)]
        rows.append("| " + " | ".join([*cells, *params, _reason(t)]) + " |")
    return "\n".join(rows)


def _reason(trial: optuna.trial.FrozenTrial) -> str:
    """Why the trial ended, and which trial a retry resumes.

    A retry starts with a copy of the failed trial's user attributes, its reason included; that reason
    is the retry's own only once the retry itself ended pruned or failed.
    """
    own = trial.user_attrs.get(REASON_ATTR, "")
    retried = trial.system_attrs.get(RETRY_OF_ATTR)
    if retried is None:
        return own
    ended = trial.state in (TrialState.PRUNED, TrialState.FAIL)
    return f"retry of trial {retried}" + (f": {own}" if ended and own else "")


def _minutes(trial: optuna.trial.FrozenTrial) -> str:
    if trial.datetime_start is None or trial.datetime_complete is None:
        return ""
    return f"{(trial.datetime_complete - trial.datetime_start).total_seconds() / 60:.1f}"


def importances(study: optuna.Study) -> dict[str, float]:
    """PED-ANOVA parameter importances over the finished trials ({} while too few have finished)."""
    finished = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE, TrialState.PRUNED))
    if len(finished) < 2:
        return {}
    try:
        evaluator = optuna.importance.PedAnovaImportanceEvaluator()
        return optuna.importance.get_param_importances(study, evaluator=evaluator)
    except (ValueError, RuntimeError):  # e.g. every finished trial has the same value
        return {}


def show(name: str, root: str, storage_url: str | None) -> str:
    """The trials table and the parameter importances of a study, as markdown."""
    study, _ = load_existing_study(name, root, storage_url)
    lines = [f"study {name!r}: {len(study.trials)} trials", "", trials_table(study), ""]
    found = importances(study)
    if found:
        lines += ["parameter importances (PED-ANOVA):", *(f"- {k}: {v:.3f}" for k, v in found.items())]
    else:
        lines.append("parameter importances: not enough finished trials yet")
    return "\n".join(lines)


def _short(value: object) -> str:
    return f"{value:.3g}" if isinstance(value, float) else str(value)


def _objective_name(settings: dict) -> str:
    """What a study's trial values are (its stored objective; studies stored before it: the return)."""
    objective = settings.get("objective", "return")
    if objective == "return":
        return "return"
    return f"{'headline metric' if objective == 'metric' else objective} (+{TIE_BREAK:g} x return)"

"""A submission: one method's result on one (task, hand, obs mode), in the form ``roto results``
sets beside roto's baselines (docs/submissions.md is its schema, versioned by ``format``).

A submission holds, for each of its training seeds, the per-episode measures of roto's evaluation
protocol (``roto.eval.evaluate.evaluate_policy``: at least ``EVAL_EPISODES`` episodes of the
benchmark's own task from ``EVAL_SEED``, no training aids). ``check_submission`` refuses one that
cannot stand in the table, naming the field; ``submission_summaries`` turns one into the cell
summaries ``roto results`` reads, so a method and roto's baselines share the same statistics.
"""

from __future__ import annotations

import pathlib
import re
from collections.abc import Mapping
from typing import Any

import numpy as np

from roto.artifact_formats import FORMAT_KEY, check_format, format_stamp
from roto.envs.config import EnvConfig
from roto.envs.observations import OBS_MODES, TOUCH_MODES
from roto.eval.protocol import EVAL_EPISODES, EVAL_SEED
from roto.olympiad.results import json_kind, require_fields
from roto.result_files import read_json
from roto.robots import ROBOTS
from roto.tasks import TASKS, get_task

MIN_SEEDS = 3
"""Training seeds a submission holds at least: fewer give no interquartile mean or interval."""
NO_TOUCH = "none"
"""The touch of a ``proprio`` submission, whose agent reads no tactile group."""
METHOD_NAME = re.compile(r"[a-z0-9][a-z0-9_.-]{0,39}")
URL = re.compile(r"https?://\S+")
"""What a method's optional ``url`` must look like: a web address, where the method is described."""
FIELDS = {
    FORMAT_KEY: int,
    "task": str,
    "task_version": int,
    "robot": str,
    "obs": str,
    "touch": str,
    "method": dict,
    "env_steps": int,
    "evaluation": dict,
    "seeds": list,
}
"""The top-level fields of a submission, with their JSON types."""


def _choice(where: str, field: str, value: str, valid: list[str]) -> None:
    if value not in valid:
        raise ValueError(f"{where}: {field!r} is {value!r}; valid: {valid}")


def required_measures(task: str) -> tuple[str, ...]:
    """The per-episode measures a submission on ``task`` holds for each seed: the task's metrics
    and path metrics (Baoding: swaps, rotations, net turns, travelled turns, round rotations)."""
    spec = get_task(task)
    return (*spec.metric_names, *spec.path_metric_names)


def check_submission(path: str | pathlib.Path, data: Any) -> dict:
    """``data``, read from ``path``, if it is a submission ``roto results`` can set in its table;
    else a ValueError naming the file, the field, what was expected and what was found."""
    where = f"submission {str(path)!r}"
    if not isinstance(data, dict):
        raise ValueError(f"{where} holds {json_kind(data)}, not an object (docs/submissions.md)")
    require_fields(where, data, FIELDS, "a submission has")
    check_format("submission", data[FORMAT_KEY], where)
    _choice(where, "task", data["task"], sorted(TASKS))
    version = get_task(data["task"]).version
    if data["task_version"] != version:
        raise ValueError(
            f"{where}: 'task_version' is {data['task_version']}, but this roto's {data['task']} is version "
            f"{version}: results of another version of the task do not compare (evaluate on this one)"
        )
    _choice(where, "robot", data["robot"], sorted(ROBOTS))
    _choice(where, "obs", data["obs"], list(OBS_MODES))
    touches = [NO_TOUCH] if data["obs"] == "proprio" else list(TOUCH_MODES)
    _choice(where, f"touch (obs {data['obs']})", data["touch"], touches)
    _check_method(where, data["method"])
    if data["env_steps"] < 1:
        raise ValueError(f"{where}: 'env_steps' (the training budget per seed) should be >= 1, got {data['env_steps']}")
    episodes = _check_evaluation(where, data["evaluation"])
    _check_seeds(where, data["seeds"], required_measures(data["task"]), episodes)
    return data


def _check_method(where: str, method: dict) -> None:
    require_fields(f"{where}: 'method'", method, {"name": str, "description": str})
    if not METHOD_NAME.fullmatch(method["name"]):
        raise ValueError(
            f"{where}: method 'name' {method['name']!r} should be 1-40 characters of a-z, 0-9, '_', '.', '-' "
            "(it names the method's column)"
        )
    if not method["description"].strip():
        raise ValueError(f"{where}: method 'description' is empty; say what the method is and what it trained with")
    url, commit = method.get("url"), method.get("commit")
    if url is not None and not (isinstance(url, str) and URL.fullmatch(url)):
        raise ValueError(f"{where}: method 'url' should be a web address (http:// or https://...), got {url!r}")
    if commit is not None and not (isinstance(commit, str) and commit.strip()):
        raise ValueError(f"{where}: method 'commit' should be a string, got {commit!r}")


def _check_evaluation(where: str, evaluation: dict) -> int:
    """The episodes per seed of a submission's ``evaluation``, if it followed roto's protocol."""
    where = f"{where}: 'evaluation'"
    require_fields(where, evaluation, {"episodes": int, "seed": int, "training_aids": dict})
    if evaluation["episodes"] < EVAL_EPISODES:
        raise ValueError(
            f"{where}: 'episodes' is {evaluation['episodes']}; roto's protocol evaluates >= {EVAL_EPISODES} episodes"
        )
    if evaluation["seed"] != EVAL_SEED:
        raise ValueError(f"{where}: 'seed' is {evaluation['seed']}; roto's protocol evaluates from seed {EVAL_SEED}")
    if evaluation["training_aids"]:
        raise ValueError(
            f"{where}: 'training_aids' is {evaluation['training_aids']}; evaluation is the benchmark's own task, "
            "without training aids ({})"
        )
    return evaluation["episodes"]


def _check_seeds(where: str, seeds: list, measures: tuple[str, ...], episodes: int) -> None:
    if len(seeds) < MIN_SEEDS:
        raise ValueError(f"{where}: 'seeds' holds {len(seeds)} training seed(s); a submission holds >= {MIN_SEEDS}")
    seen: set[int] = set()
    for i, entry in enumerate(seeds):
        here = f"{where}: seeds[{i}]"
        if not isinstance(entry, dict):
            raise ValueError(f"{here} should be an object, found {json_kind(entry)}")
        require_fields(here, entry, {"seed": int, "per_episode": dict})
        if entry["seed"] in seen:
            raise ValueError(f"{here}: training seed {entry['seed']} appears twice; each seed is one training run")
        seen.add(entry["seed"])
        for name in measures:
            _check_episodes(f"{here}: per_episode {name!r}", entry["per_episode"], name, episodes)


def _check_episodes(where: str, per_episode: dict, name: str, episodes: int) -> None:
    """Refuse a seed's measure ``name`` unless it is a list of ``episodes`` finite numbers."""
    values = per_episode.get(name)
    if not isinstance(values, list):
        found = json_kind(values) if name in per_episode else "no such field"
        raise ValueError(f"{where} should be a list (one value per episode), found {found}")
    if len(values) != episodes:
        raise ValueError(f"{where} holds {len(values)} values; 'evaluation' says {episodes} episodes")
    bad = [v for v in values if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v)]
    if bad:
        raise ValueError(f"{where} holds {json_kind(bad[0])}; every value is a finite number")


def read_submission(path: str | pathlib.Path) -> dict:
    """The submission in ``path``, checked (``check_submission``)."""
    return check_submission(path, read_json(path, "submission"))


def _evaluation(per_episode: dict[str, list[float]], lead: str | None) -> dict[str, Any]:
    """A cell summary's ``final``/``best`` record of a seed's episodes: each measure's mean and std."""
    record: dict[str, Any] = {}
    for name, values in sorted(per_episode.items(), key=lambda item: item[0] != lead):
        record[f"{name}_mean"] = float(np.mean(values))
        record[f"{name}_std"] = float(np.std(values))
    return {**record, "per_episode": per_episode}


def submission_summaries(submission: dict, source: str = "") -> list[dict]:
    """One cell summary per seed of a checked submission: its method is the column (``variant``),
    its submitted policy both the final and the best one, with no learning curve."""
    method = submission["method"]
    lead = get_task(submission["task"]).selection_metric
    label = f"{method['description']} (submitted; touch {submission['touch']}, {submission['env_steps']:,} env steps)"
    return [
        {
            **format_stamp("cell summary"),
            **{key: submission[key] for key in ("task", "robot", "obs", "task_version", "env_steps")},
            "variant": method["name"],
            "seed": entry["seed"],
            "plan": f"submission {source}".strip(),
            "agent": {"label": label, "roto_agent": None},
            "commit": str(method.get("commit", "submitted")),
            "evaluations": [],
            "final": _evaluation(entry["per_episode"], lead),
            "best": _evaluation(entry["per_episode"], lead),
        }
        for entry in submission["seeds"]
    ]


def make_submission(
    config: EnvConfig,
    results: Mapping[int, Mapping[str, Any]],
    method: Mapping[str, str],
    env_steps: int,
) -> dict:
    """A submission of ``results`` ({training seed: what ``evaluate_policy`` returned for that seed's
    policy on ``config``'s task, hand and obs mode}), checked before it is returned.

    ``method``: {"name": the column's name, "description": what the method is and trained with,
    and optionally "url", "commit"}; ``env_steps``: the training budget of each seed."""
    episodes = {r.get("episodes") for r in results.values()}
    seeds = {r.get("seed") for r in results.values()}
    for name, found in (("episodes", episodes), ("seed", seeds)):
        if len(found) > 1:
            raise ValueError(
                f"the seeds' results were evaluated with different {name!r} {sorted(map(str, found))}; "
                f"roto's protocol evaluates every seed's policy alike ({EVAL_EPISODES} episodes from seed {EVAL_SEED})"
            )
    data = {
        **format_stamp("submission"),
        "task": config.task,
        "task_version": get_task(config.task).version,
        "robot": config.robot,
        "obs": config.obs_mode,
        "touch": NO_TOUCH if config.obs_mode == "proprio" else config.touch,
        "method": dict(method),
        "env_steps": int(env_steps),
        "evaluation": {"episodes": next(iter(episodes), 0), "seed": next(iter(seeds), None), "training_aids": {}},
        "seeds": [
            {"seed": int(seed), "per_episode": dict(result["per_episode"])} for seed, result in sorted(results.items())
        ],
    }
    return check_submission("(being made)", data)


def with_submissions(summaries: list[dict], folder: str | pathlib.Path) -> list[dict]:
    """``summaries`` and the cell summaries of every submission in ``folder`` (``*.json``); refused
    where a method's name is already a column of the same (task, hand, obs mode)."""
    paths = sorted(pathlib.Path(folder).glob("*.json"))
    if not paths:
        raise FileNotFoundError(f"--submissions {str(folder)!r} holds no submission (*.json, docs/submissions.md)")
    taken = {(s["task"], s["robot"], s["obs"], s["variant"]): s.get("plan") or "the baselines" for s in summaries}
    out = list(summaries)
    for path in paths:
        rows = submission_summaries(read_submission(path), path.name)
        cell = (rows[0]["task"], rows[0]["robot"], rows[0]["obs"], rows[0]["variant"])
        if cell in taken:
            raise ValueError(
                f"submission {str(path)!r}: method {cell[3]!r} is already a column of {'/'.join(cell[:3])} "
                f"({taken[cell]}); give the method another name"
            )
        taken[cell] = rows[0]["plan"]
        out += rows
    return out

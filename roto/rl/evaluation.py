"""Training-time evaluation: the current weights, frozen, one full episode per evaluation env.

Each evaluation resets the evaluation envs with the same seed (so every evaluation of a run starts
from the same episode starts), runs the deterministic (mean) action until every env has finished
its first episode, and appends one JSON line to ``<run_dir>/evaluations.jsonl``.
"""

from __future__ import annotations

import json
import math
import pathlib
import time
import warnings
from typing import Any

import torch

from roto.envs.ball_paths import first_episodes_with_paths
from roto.result_files import write_text_atomic
from roto.rl.networks import ActorCritic
from roto.rl.torch_threads import single_torch_thread

EVALUATIONS_NAME = "evaluations.jsonl"


def summarize(per_episode: dict[str, list[float]]) -> dict[str, float]:
    """{"<name>_mean", "<name>_std"} (population std) of each per-episode list."""
    summary = {}
    for name, values in per_episode.items():
        t = torch.tensor(values, dtype=torch.float64)
        summary[f"{name}_mean"] = float(t.mean())
        summary[f"{name}_std"] = float(t.std(unbiased=False)) if len(values) > 1 else 0.0
    return summary


def best_eval_key(record: dict[str, Any], selection_metric: str | None) -> tuple[float, float]:
    """How an evaluation ranks for ``best.pt``: (the mean of the task's ``selection_metric``, the
    mean return), compared in that order; the return alone (twice) for a task without one. Baoding
    selects by round rotations, so a policy that swings the balls out and back (paid by the return
    as a rotation would be) never displaces one that carries them round. A record from before the
    metric was measured ranks below every record that has it (-inf), as its checkpoint does
    (``load_best_eval``)."""
    ret = float(record["return_mean"])
    return (float(record.get(f"{selection_metric}_mean", -math.inf)) if selection_metric else ret, ret)


def load_best_eval(state: dict[str, Any], selection_metric: str | None) -> tuple[float, float]:
    """``best_eval_key`` of a checkpoint's best evaluation; for a checkpoint of format 1 or 2, which
    kept only the best return (``best_eval_return``), that return (the metric unknown: -inf, so the
    next evaluation takes ``best.pt`` over)."""
    if "best_eval" in state:
        metric, ret = state["best_eval"]
        return float(metric), float(ret)
    ret = float(state["best_eval_return"])
    return (-math.inf if selection_metric else ret, ret)


class PolicyEvaluator:
    """Evaluates a policy on its own envs, which step only while it evaluates.

    Args:
        env: the evaluation envs (B of them: B episodes per evaluation).
        seed: reset seed of every evaluation.
        run_dir: where ``evaluations.jsonl`` is appended to.
    """

    def __init__(self, env: Any, seed: int, run_dir: pathlib.Path) -> None:
        self.env, self.seed = env, seed
        self.path = run_dir / EVALUATIONS_NAME

    @torch.no_grad()
    def evaluate(self, model: ActorCritic, **fields: float) -> dict[str, Any]:
        """Run one episode per env with ``model``'s mean action; append and return the record.

        ``fields`` (update, env steps, training wall time ...) lead the record; then the mean and
        std of the return, length, each task metric and path metric, and the per-episode lists.
        """
        start = time.perf_counter()
        obs, _ = self.env.reset(seed=self.seed)
        was_training = model.training
        model.eval()
        with single_torch_thread(self.env.device):
            per_episode = first_episodes_with_paths(self.env, model.act_deterministic, obs)
        model.train(was_training)
        record = {**fields, "eval_s": time.perf_counter() - start, **summarize(per_episode)}
        record["per_episode"] = per_episode
        with self.path.open("a") as f:
            f.write(json.dumps(record) + "\n")
        return record

    def drop_after(self, update: int) -> None:
        """Forget records of updates after ``update`` (a resumed run repeats them), and a torn last
        line; written atomically."""
        if self.path.is_file():
            kept = [json.dumps(r) for r in read_evaluation_records(self.path) if r["update"] <= update]
            write_text_atomic(self.path, "".join(line + "\n" for line in kept))


def read_evaluation_records(path: pathlib.Path) -> list[dict[str, Any]]:
    """The records of an ``evaluations.jsonl``. A torn last line (a crash mid-write) is skipped with a
    warning; a broken line before it is a ValueError naming the file and the line."""
    lines = [line for line in path.read_text().splitlines() if line.strip()]
    records = []
    for number, line in enumerate(lines, start=1):
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            if number < len(lines):
                raise ValueError(f"{str(path)!r} line {number} is not a JSON record: {line[:80]!r}") from None
            warnings.warn(f"{str(path)!r}: skipped a torn last line (a write cut off): {line[:80]!r}", stacklevel=2)
    return records


def read_evaluations(run_dir: str | pathlib.Path) -> list[dict[str, Any]]:
    """Every record of ``<run_dir>/evaluations.jsonl`` (empty if there is none)."""
    path = pathlib.Path(run_dir) / EVALUATIONS_NAME
    return read_evaluation_records(path) if path.is_file() else []

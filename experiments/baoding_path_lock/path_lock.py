"""When does a Baoding run's path (round or out-and-back swing) settle? Reads every committed Baoding
cell summary under experiments/ and prints, per run, the path of its training-time evaluations at
the first with at least one rotation (roto's count) and three evaluations later, and the path of
its ``best.pt`` over 100 fresh episodes.

    python experiments/baoding_path_lock/path_lock.py > experiments/baoding_path_lock/path_lock.md

A path is Baoding's ``Task.path_kind`` of an evaluation's means: "round" where the mean net turns
are at least 0.8 of the mean rotations, "swing" where not, "no swaps" below one rotation.
"""

from __future__ import annotations

import json
import pathlib

from roto.tasks import get_task

ROOT = pathlib.Path(__file__).resolve().parents[2]
LATER = 3


def path(rotations: float, net_turns: float) -> str:
    """The path kind of one evaluation's means (the task's own rule)."""
    return get_task("baoding").path_kind({"rotations": rotations, "net_turns": net_turns})


def row(summary: dict, name: str) -> str | None:
    """One markdown row, or None for a summary without the pair's turns."""
    evaluations = summary.get("evaluations") or []
    if not evaluations or "net_turns_mean" not in evaluations[0]:
        return None
    swapping = [e for e in evaluations if e["rotations_mean"] >= 1.0]
    kinds = [path(e["rotations_mean"], e["net_turns_mean"]) for e in swapping[: LATER + 1]]
    first = f"{swapping[0]['env_steps'] / 1e6:.2f} M" if swapping else "never"
    best = summary["best"]
    final = path(best["rotations_mean"], best["net_turns_mean"])
    cells = [
        name, summary["robot"], str(summary["seed"]), first,
        kinds[0] if kinds else "", kinds[LATER] if len(kinds) > LATER else "",
        f"{final} ({best['rotations_mean']:.2f} / {best['net_turns_mean']:.2f})",
    ]  # fmt: skip
    return "| " + " | ".join(cells) + " |"


def main() -> None:
    columns = ("summary", "hand", "seed", "first evaluation ≥ 1 rotation", "its path", "3 evaluations later")
    print("| " + " | ".join(columns) + " | best.pt (rotations / net turns) |")
    print("|---|---|---|---|---|---|---|")
    for file in sorted((ROOT / "experiments").glob("*/results*/**/*.json")):
        summary = json.loads(file.read_text())
        if isinstance(summary, dict) and summary.get("task") == "baoding" and "best" in summary:
            line = row(summary, str(file.relative_to(ROOT / "experiments")))
            if line:
                print(line)


if __name__ == "__main__":
    main()

"""When each blind Baoding seed's training latch radius (the tolerance curriculum's) reached the
task's 1 cm, the widest it was from then on, and the radius with the training episodes' rotations
at fixed env steps, read from committed cell summaries.

    python experiments/baoding_turn_latch/latch_radius.py experiments/baoding_hold_every_hand/results/*.json
"""

import json
import pathlib
import sys

MARKS_M = (1, 2, 3, 5, 7.5, 10, 15, 20)
NARROWED_M = 0.0105  # within 0.5 mm of the task's 1 cm


def nearest(training: list[dict], env_steps: float) -> dict:
    return min(training, key=lambda row: abs(row["env_steps"] - env_steps))


def describe(summary: dict) -> str:
    training = summary["training"]
    narrowed = next((r["env_steps"] / 1e6 for r in training if r["train/success_radius"] <= NARROWED_M), None)
    marks = []
    for m in MARKS_M:
        if m * 1e6 <= summary["env_steps"] + 1e5:
            row = nearest(training, m * 1e6)
            marks.append(f"{m:g} M {100 * row['train/success_radius']:.2f} cm / {row['train/episode_rotations']:.2f}")
    reached = f"{narrowed:.2f} M" if narrowed is not None else "not reached"
    if narrowed is not None:
        after = [r["train/success_radius"] for r in training if r["env_steps"] >= narrowed * 1e6]
        reached += f" (widest from then on {100 * max(after):.2f} cm)"
    best = summary["best"]["round_rotations_mean"]
    return f"{summary['robot']} seed {summary['seed']} (best {best:.2f}): 1 cm {reached}; " + ", ".join(marks)


if __name__ == "__main__":
    for path in sys.argv[1:]:
        print(describe(json.loads(pathlib.Path(path).read_text())))

"""Which of the benchmark's Baoding evaluation episodes end early, from the committed summaries:
per cell, the `best.pt` episodes (of 100) that end before a number of control steps (a ball lost),
their lengths and round rotations, and the cell's mean round rotations over all its episodes and
over the others.

    python experiments/baoding_benchmark_cells/early_drops.py [--before 150] [--obs blind]

Reads benchmarks/results/benchmark/cells/baoding-*.json (run from the repository root); prints
one line per cell and one per hand (its early episodes, 100 a seed, and the means over its seeds).
"""

import argparse
import json
import pathlib
import statistics

CELLS = pathlib.Path("benchmarks/results/benchmark/cells")


def early_episodes(summary: dict, before: int) -> tuple[list[tuple[int, float]], float, float]:
    """([(length, round rotations)] of the episodes shorter than ``before`` control steps, the mean
    round rotations over every episode, over the other episodes)."""
    episodes = summary["best"]["per_episode"]
    pairs = list(zip(episodes["length"], episodes["round_rotations"], strict=True))
    early = sorted((int(length), rotations) for length, rotations in pairs if length < before)
    rest = [rotations for length, rotations in pairs if length >= before]
    return early, statistics.mean(r for _, r in pairs), statistics.mean(rest)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=int, default=150, help="control steps (600 in a full episode)")
    parser.add_argument("--obs", default="blind", choices=["blind", "state", "proprio"])
    args = parser.parse_args()
    hands: dict[str, list[tuple[float, float, int]]] = {}
    for path in sorted(CELLS.glob(f"baoding-*-{args.obs}-ppo-seed*.json")):
        summary = json.loads(path.read_text())
        early, every, rest = early_episodes(summary, args.before)
        hands.setdefault(summary["robot"], []).append((every, rest, len(early)))
        lengths = ", ".join(str(length) for length, _ in early)
        print(f"{path.stem:<36} {len(early):>2} early ({lengths or '-'}); {every:.2f} all, {rest:.2f} the others")
    for hand, means in hands.items():
        every, rest = (statistics.mean(m[i] for m in means) for i in (0, 1))
        early = sum(m[2] for m in means)
        print(f"{hand:<12} {len(means)} seeds, {early} early of {100 * len(means)} episodes: mean {every:.2f} over all "
              f"episodes, {rest:.2f} over the others")  # fmt: skip


if __name__ == "__main__":
    main()

"""Each Bounce cell's rhythm: control steps per bounce in the episodes that keep the ball.

Reads the cell summaries (``best`` over 100 fresh episodes) and prints, per cell, the mean
bounces, how many episodes ran the full 600 control steps, the most common bounce counts among
those, and the control steps a bounce that the most common count means. Bounce's counter needs
5 steps without contact before a new contact, so one bounce takes at least 6 control steps
(100 bounces in 600).

    python experiments/bounce_probes/rhythm.py benchmarks/results/benchmark/cells
"""

import argparse
import collections
import json
from pathlib import Path

EPISODE_STEPS = 600


def rhythm(summary: dict) -> dict:
    """Bounce statistics of one cell summary's ``best`` evaluation."""
    episodes = summary["best"]["per_episode"]
    bounces, lengths = episodes["bounces"], episodes["length"]
    full = [b for b, n in zip(bounces, lengths, strict=True) if n >= EPISODE_STEPS]
    common = collections.Counter(full).most_common(2)
    mode = common[0][0] if common else 0.0
    return {
        "mean": sum(bounces) / len(bounces),
        "full": len(full),
        "episodes": len(bounces),
        "common": common,
        "steps_per_bounce": EPISODE_STEPS / mode if mode else None,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cells", type=Path, help="folder of cell summaries (*.json)")
    args = parser.parse_args()
    for path in sorted(args.cells.glob("bounce-*.json")):
        r = rhythm(json.loads(path.read_text()))
        common = ", ".join(f"{int(b)} ({n})" for b, n in r["common"]) or "-"
        steps = f"{r['steps_per_bounce']:.2f}" if r["steps_per_bounce"] else "-"
        print(
            f"{path.stem:38s} mean {r['mean']:5.1f}  full {r['full']:3d}/{r['episodes']}"
            f"  most common {common:18s}  steps a bounce {steps}"
        )


if __name__ == "__main__":
    main()

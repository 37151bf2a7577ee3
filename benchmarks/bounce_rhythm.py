"""Where a Bounce policy's count comes from: its period split into touch and flight, and the ball's rise.

    python benchmarks/bounce_rhythm.py RUN_DIR_OR_CHECKPOINT [...] [--envs 16] [--seed 1000000] [--json FILE]

For each checkpoint (a run directory means its ``best.pt``): one episode per env with the deterministic
policy on the CPU backend, then ``roto.eval.bounce_rhythm.rhythm``'s figures, one line per checkpoint.
The bounce rule needs 5 control steps of flight, so a period is at least 6 steps (100 bounces per 10 s);
80 bounces need a period of 7.5 steps, roto v1's 69 one of 8.7.
"""

from __future__ import annotations

import argparse
import json
import pathlib

from roto.eval.bounce_rhythm import record_rhythm, rhythm
from roto.rl.run_dir import RunDir, load_policy


def checkpoint_of(path: str) -> pathlib.Path:
    """``path`` itself, or a run directory's ``best.pt``."""
    given = pathlib.Path(path)
    return RunDir(given).checkpoint("best") if given.is_dir() else given


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoints", nargs="+", help="checkpoints (.pt) or run directories (their best.pt)")
    parser.add_argument("--envs", type=int, default=16, help="episodes, one per env")
    parser.add_argument("--seed", type=int, default=1_000_000, help="the envs' seed (roto eval's default)")
    parser.add_argument("--json", help="write every checkpoint's figures to this file")
    args = parser.parse_args()
    figures = {}
    for path in args.checkpoints:
        checkpoint = checkpoint_of(path)
        model, spec = load_policy(checkpoint)
        figures[str(checkpoint)] = rhythm(*record_rhythm(model, spec, envs=args.envs, seed=args.seed))
        print(checkpoint, " ".join(f"{name} {value:.2f}" for name, value in figures[str(checkpoint)].items()))
    if args.json:
        pathlib.Path(args.json).write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()

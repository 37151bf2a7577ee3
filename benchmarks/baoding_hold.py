"""The Baoding hold policy on every hand: dense return, swaps, and how often the dropped balls are lost.

python benchmarks/baoding_hold.py --envs 64 --out benchmarks/results/baoding_reference/hold.json
"""

from __future__ import annotations

import argparse
import json
import pathlib

import torch

from roto.reference.hold import run_hold
from roto.robots import ROBOTS


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--envs", type=int, default=64, help="episodes per hand (one per env)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=pathlib.Path, default=None)
    args = parser.parse_args()
    torch.set_num_threads(1)
    rows = [run_hold("baoding", robot, num_envs=args.envs, seed=args.seed) for robot in sorted(ROBOTS)]
    for row in rows:
        print(json.dumps(row))
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()

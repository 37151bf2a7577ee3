"""The Baoding hold policy on every hand: dense return, swaps, and how often the dropped balls are lost.

python benchmarks/baoding_hold.py --envs 64 --out benchmarks/results/baoding_reference/hold.json
python benchmarks/baoding_hold.py --envs 64 --noise 0 0.25 0.5 1 --out FILE.json

``--noise`` adds Gaussian noise of each given std to every action (actions span the joint ranges
as [-1, 1]): how much of a fresh policy's exploration noise (roto's starts at std 1) each hand
survives before it drops the balls.
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
    parser.add_argument("--noise", type=float, nargs="+", default=[0.0], help="action noise stds, one row each")
    parser.add_argument("--robots", nargs="+", default=sorted(ROBOTS), choices=sorted(ROBOTS))
    parser.add_argument("--out", type=pathlib.Path, default=None)
    args = parser.parse_args()
    if min(args.noise) < 0:
        parser.error(f"--noise stds must be >= 0, got {args.noise}")
    torch.set_num_threads(1)
    rows = [
        run_hold("baoding", robot, num_envs=args.envs, seed=args.seed, action_noise=sigma)
        for robot in args.robots
        for sigma in args.noise
    ]
    for row in rows:
        print(json.dumps(row))
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()

"""Fingerprints of short trainings of packaged recipes: a hash of the final weights and of the
physics state, and the last scalars. A refactor that claims to change no result leaves them equal
on the same machine and build (floating-point results may differ across CPUs and torch builds):

    python benchmarks/training_fingerprint.py --out /tmp/after.json
    python benchmarks/training_fingerprint.py --compare benchmarks/results/training_fingerprint.json

Each case trains 6 PPO updates of 8 envs and 16 rollouts (small networks) with every training aid
its recipe carries.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import pathlib
import sys
import tempfile

import torch

from roto.rl.run_spec import build_run_spec
from roto.rl.runner import Trainer

CASES = {
    "shadow_all_aids": ("baoding", "shadow", "experiments/baoding_configs/baoding_cpu_shadow.yaml"),
    "orca_round": ("baoding", "orca", "experiments/baoding_configs/baoding_cpu_orca_round.yaml"),
    "lite": ("baoding", "shadow_lite", "experiments/baoding_configs/baoding_cpu_shadow_lite.yaml"),
    "bounce_quick": ("bounce", "shadow", "bounce_cpu_quickstart"),
}
SMALL = [
    *("network.encoder=[32]", "network.policy_head=[16]", "network.value_head=[16]", "ppo.rollouts=16"),
    *("ppo.epochs=1", "ppo.minibatches=2", "run.num_eval_envs=2", "run.eval_every=2"),
]


def fingerprint(task: str, robot: str, config: str) -> dict:
    """The weights' and physics' hashes and the last scalars of one short training."""
    overrides = [*SMALL, "env.aids.replayed_starts.record_capacity=64"] if task == "baoding" else SMALL
    spec = build_run_spec(task, robot, "blind", config, overrides, 16 * 8 * 6, num_envs=8, seed=3)
    with (
        tempfile.TemporaryDirectory() as folder,
        Trainer.open(pathlib.Path(folder) / "run", spec, tensorboard=False) as trainer,
    ):
        last = trainer.train(progress=False)
        weights = hashlib.sha256()
        for name, value in sorted(trainer.model.state_dict().items()):
            weights.update(name.encode())
            weights.update(value.detach().cpu().numpy().tobytes())
        physics = hashlib.sha256(trainer.env.state_dict()["physics"].numpy().tobytes())
        return {"weights": weights.hexdigest()[:16], "physics": physics.hexdigest()[:16], "last": dict(last)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", help="write the fingerprints here (JSON)")
    parser.add_argument("--compare", help="a fingerprints JSON to compare with; exit 1 where any differs")
    args = parser.parse_args()
    torch.set_num_threads(1)
    found = {}
    for name, case in CASES.items():
        found[name] = fingerprint(*case)
        print(name, found[name]["weights"], found[name]["physics"], flush=True)
    if args.out:
        pathlib.Path(args.out).write_text(json.dumps(found, indent=1, sort_keys=True) + "\n")
    if args.compare:
        expected = json.loads(pathlib.Path(args.compare).read_text())
        differ = [
            n
            for n in CASES
            if {k: found[n][k] for k in ("weights", "physics")} != {k: expected[n][k] for k in ("weights", "physics")}
        ]
        print("identical" if not differ else f"differ: {differ}")
        return 1 if differ else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())

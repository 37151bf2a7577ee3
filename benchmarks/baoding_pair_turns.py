"""Do a Baoding policy's balls go round each other, or swing back and forth? (roto/eval/pair_turns.py)

python benchmarks/baoding_pair_turns.py --episodes 16 --out FILE.json CHECKPOINT [CHECKPOINT ...]

For each checkpoint: the benchmark's own task (the evaluation's starts, the mean action), one episode
per env, and per episode its rotations (swaps / 2), the net turns of the line between the balls
and the turns it travelled in all. A pair carried round one way has net turns close to its
rotations; a pair swung out and back has net turns near 0 and travelled turns close to the
rotations.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import statistics

import torch

from roto.envs.episodes import first_episodes
from roto.envs.roto_env import RotoEnv
from roto.eval.pair_turns import pair_turns
from roto.rl.run_dir import load_policy


@torch.no_grad()
def turns_of(checkpoint: pathlib.Path, episodes: int, seed: int) -> dict[str, object]:
    model, settings, _ = load_policy(checkpoint)
    if settings.env.task != "baoding":
        raise ValueError(f"{checkpoint} was trained on task {settings.env.task!r}; this measures 'baoding' policies")
    groups = tuple(dict.fromkeys((*settings.env.extra_groups, "privileged")))  # the balls' state beside the policy's
    env = RotoEnv(settings.cpu_env_config(num_envs=episodes, seed=seed, extra_groups=groups))
    frame = 6 * len(env.balls)  # per ball (x, y, z, vx, vy, vz), newest frame last in the stack
    positions: list[torch.Tensor] = []

    def act(obs: dict[str, torch.Tensor]) -> torch.Tensor:  # the observation each action answers
        positions.append(obs["privileged"][:, -frame:].reshape(-1, len(env.balls), 6)[..., :3].clone())
        return model.act_deterministic(obs)

    obs, _ = env.reset(seed=seed)
    result = first_episodes(env, act, obs)
    env.close()
    path = torch.stack(positions)  # (steps, episodes, 2, 3): observation t of each env, t = 0 at its reset
    lengths = result["length"][:, 0].long().tolist()
    turns = [pair_turns(path[:length, i]) for i, length in enumerate(lengths)]  # the first episode's own frames
    rows = {
        "rotations": [s / 2 for s in result["swaps"][:, 0].tolist()],
        "net_turns": [net for net, _ in turns],
        "travelled_turns": [travelled for _, travelled in turns],
        "length": lengths,
    }
    summary = {f"{key}_mean": statistics.fmean(values) for key, values in rows.items()}
    return {"checkpoint": str(checkpoint), "robot": settings.env.robot, "episodes": episodes, **summary, **rows}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("checkpoints", type=pathlib.Path, nargs="+")
    parser.add_argument("--episodes", type=int, default=16)
    parser.add_argument("--seed", type=int, default=1_000_000, help="the evaluation's seed by default")
    parser.add_argument("--out", type=pathlib.Path, default=None)
    args = parser.parse_args()
    records = []
    for checkpoint in args.checkpoints:
        record = turns_of(checkpoint, args.episodes, args.seed)
        records.append(record)
        print(
            f"{record['robot']}: rotations {record['rotations_mean']:.2f}, net turns {record['net_turns_mean']:.2f}, "
            f"travelled turns {record['travelled_turns_mean']:.2f} ({checkpoint})",
            flush=True,
        )
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(records, indent=1) + "\n")


if __name__ == "__main__":
    main()

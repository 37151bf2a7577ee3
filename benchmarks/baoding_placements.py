"""Where the raised Baoding target can go on each hand: every sign choice of roto's diagonal stack
(and, on the Allegro, its side-by-side pair), scored by what decides a placement.

For each candidate: how deep a ball on the second target sits inside the hand at the default pose
(with ball a on T_palm), the hold policy's return and swaps over 16 episodes (a placement that
hands out swaps for holding still is no task), and the swaps of one short episode of the reference
controller (a placement it cannot swap on may be impossible). And where to drop the balls from:
12 noisy drops above the palm centre and above the hand's chosen drop centre, the hand holding its
default pose for 10 s, counting the pairs it loses.

    python benchmarks/baoding_placements.py --steps 300 --out benchmarks/results/baoding_reference/placements.json
"""

from __future__ import annotations

import argparse
import itertools
import json
import pathlib

import mujoco
import numpy as np
import torch

import roto.robots as robots
from roto.reference.baoding_controller import BaodingReference, reference_env, run_reference_episode
from roto.reference.baoding_cost import BaodingCostWeights
from roto.reference.hold import run_hold
from roto.reference.predictive_sampling import PredictiveSampling, SamplingConfig
from roto.robots.spec import RobotSpec, diagonal_stack, side_by_side, with_baoding_geometry
from roto.sim.scene import build_scene
from roto.tasks.baoding import MAX_SEPARATION, RESET_NOISE, baoding_balls, drop_positions, geometry_of
from roto.tasks.base import PALM_DROP_LIMIT


def candidates(robot: RobotSpec) -> dict[str, tuple]:
    """Name -> targets: the four diagonal stacks δ·(±1, ±1, 1) on T_palm, and on the Allegro the two
    side-by-side pairs across the fingers."""
    t_palm, radius = geometry_of(robot).targets[0], geometry_of(robot).ball_radius
    out = {
        f"diagonal ({sx:+.0f}, {sy:+.0f}, +1)": diagonal_stack(t_palm, radius, (sx, sy, 1.0))
        for sx, sy in itertools.product((1.0, -1.0), (1.0, -1.0))
    }
    if robot.name == "allegro":
        for sy in (-1.0, 1.0):
            out[f"side by side (0, {sy:+.0f}, 0)"] = side_by_side(t_palm, radius, (0.0, sy, 0.0))
    return out


def target_depth(robot: RobotSpec) -> float:
    """Deepest contact (m) of a ball with the hand at the default pose, balls on their targets."""
    model, layout = build_scene(robot, baoding_balls(geometry_of(robot).ball_radius))
    data = mujoco.MjData(model)
    data.qpos[:] = layout.default_qpos
    for adr, target in zip(layout.ball_qpos, geometry_of(robot).targets, strict=True):
        data.qpos[adr : adr + 3] = target
    mujoco.mj_forward(model, data)
    balls = {model.body(name).id for name in ("ball_a", "ball_b")}
    depths = [
        -c.dist
        for c in data.contact[: data.ncon]
        if (model.geom_bodyid[c.geom1] in balls) != (model.geom_bodyid[c.geom2] in balls)
    ]
    return max([0.0, *depths])


def lost_drops(robot: RobotSpec, centre: tuple[float, float, float], drops: int = 12) -> int:
    """Of ``drops`` pairs dropped about ``centre`` (+ one shared U(±5 mm)³ offset each) onto the hand
    holding its default pose for 600 control steps, how many end the episode (parted or fallen)."""
    model, layout = build_scene(robot, baoding_balls(geometry_of(robot).ball_radius))
    rng = np.random.default_rng(0)
    start = drop_positions(torch.tensor(centre, dtype=torch.float64), geometry_of(robot).ball_radius).numpy()
    lost = 0
    for _ in range(drops):
        data = mujoco.MjData(model)
        data.qpos[:] = layout.default_qpos
        offset = rng.uniform(-RESET_NOISE, RESET_NOISE, 3)
        for adr, ball in zip(layout.ball_qpos, start, strict=True):
            data.qpos[adr : adr + 3] = ball + offset
        data.ctrl[:] = layout.default_qpos[layout.act_qpos]
        for _ in range(600):
            mujoco.mj_step(model, data, nstep=4)
            pos = np.array([data.qpos[adr : adr + 3] for adr in layout.ball_qpos])
            if pos[:, 2].min() < -PALM_DROP_LIMIT or np.linalg.norm(pos[0] - pos[1]) >= MAX_SEPARATION:
                lost += 1
                break
    return lost


def drops_row(name: str) -> dict:
    robot = robots.ROBOTS[name]
    palm_centre = (0.0, 0.0, geometry_of(robot).drop_centre[2])
    row = {
        "robot": name,
        "drop_centre": list(geometry_of(robot).drop_centre),
        "lost_of_12_at_drop_centre": lost_drops(robot, geometry_of(robot).drop_centre),
        "lost_of_12_above_palm_centre": lost_drops(robot, palm_centre),
    }
    print(json.dumps(row), flush=True)
    return row


def measure(name: str, steps: int) -> list[dict]:
    base = robots.ROBOTS[name]
    rows = []
    try:
        for label, targets in candidates(base).items():
            robot = with_baoding_geometry(base, targets=targets)
            robots.ROBOTS[name] = robot
            hold = run_hold("baoding", name, num_envs=16, seed=0)
            env = reference_env(name, seed=0, episode_steps=steps)
            lo, hi = env.indices.ctrl_lo.numpy(), env.indices.ctrl_hi.numpy()
            planner = PredictiveSampling(env.model, lo, hi, SamplingConfig(threads=2))
            episode = run_reference_episode(BaodingReference(env, planner, BaodingCostWeights()))
            planner.close()
            env.close()
            row = {
                "robot": name,
                "placement": label,
                "chosen": targets == geometry_of(base).targets,
                "targets": np.round(np.array(targets), 4).tolist(),
                "target_depth_mm": round(1000 * target_depth(robot), 1),
                "hold_return": round(hold["mean_return"], 1),
                "hold_swaps": hold["mean_swaps"],
                "reference_steps": steps,
                "reference_swaps": episode["swaps"],
                "reference_length": episode["length"],
            }
            print(json.dumps(row), flush=True)
            rows.append(row)
    finally:
        robots.ROBOTS[name] = base
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robots", nargs="+", default=sorted(robots.ROBOTS))
    parser.add_argument("--steps", type=int, default=300, help="control steps of the reference episode")
    parser.add_argument("--out", type=pathlib.Path, default=None)
    args = parser.parse_args()
    torch.set_num_threads(1)
    drops = [drops_row(name) for name in args.robots]
    placements = [row for name in args.robots for row in measure(name, args.steps)]
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps({"drops": drops, "placements": placements}, indent=1) + "\n")


if __name__ == "__main__":
    main()

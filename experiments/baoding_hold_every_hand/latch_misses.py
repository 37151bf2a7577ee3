"""How many rotations a trained Baoding policy's ball paths would count under a wider latch: a
policy that turns the pair without the task counting swaps carries the balls round on a path that
misses the 1 cm latches by more.

    python experiments/baoding_hold_every_hand/latch_misses.py CHECKPOINT [CHECKPOINT ...] [--episodes 16]

Runs the checkpoint's deterministic policy on the benchmark's task (no training aids, the
evaluation protocol's first seed), keeps the balls' centres at every step and replays the task's
own latch-and-swap rule (``roto.tasks.baoding.baoding_rule``) on them with latch radii of 1 to
4 cm. At 1 cm (the task's) the recount comes within about 1 % of the episodes' own rotations,
printed beside it as a check (the recorder keeps the balls before each action, so an episode's last
step is not replayed); net turns (``roto.tasks.pair_turns``) are what a path carried round makes.
Where the balls go round: their mean centre relative to the targets' midpoint (x along the fingers,
z up, cm; the first second of each episode, while the dropped balls settle, left out) and how near
each ball came to its nearer target in an episode (median over episodes, cm). What turn shaping
would pay if it paid only near the targets: the pair's net turning in the palm's plane (the turns
turn shaping pays, ``roto.tasks.round_swaps.pair_turn_step``) over the steps with the pair's centre
within 1, 1.5 and 2 times half the targets' separation of their midpoint.
"""

import argparse
import dataclasses
import math

import torch

from roto.envs.ball_paths import BallPathRecorder, for_path_metrics
from roto.envs.episodes import first_episodes
from roto.envs.roto_env import RotoEnv
from roto.eval.evaluate import EVAL_SEED, policy_groups
from roto.rl.run_dir import load_policy
from roto.tasks.baoding import baoding_rule, geometry_of
from roto.tasks.pair_turns import pair_turns
from roto.tasks.round_swaps import centre_offset, pair_turn_step, turn_pay_share, turn_shaping

RADII_CM = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0)
CENTRE_SCALES = (1.0, 1.5, 2.0)
SETTLE_STEPS = 60
"""Control steps (1 s) left out of ``path_offsets``: the dropped balls are still falling."""


def recounted_rotations(
    path: torch.Tensor, lengths: torch.Tensor, targets: torch.Tensor, radius: float
) -> torch.Tensor:
    """Each episode's rotations (swaps / 2) under the latch rule with ``radius`` (m).

    Args:
        path: (T, B, 2, 3) balls a and b at each step, task frame; lengths: (B,) each episode's steps;
        targets: (2, 3) T_palm, then the second target.

    Returns:
        (B,) float64.
    """
    steps, batch = path.shape[:2]
    swapped = torch.zeros(batch, dtype=torch.bool)
    latched = torch.zeros(batch, 2, dtype=torch.bool)
    swaps = torch.zeros(batch, dtype=torch.float64)
    for t in range(steps):
        _, swap, swapped, latched = baoding_rule(path[t].double(), targets, swapped, latched, radius)
        swaps += (swap & (t < lengths)).double()
    return swaps / 2


def path_offsets(path: torch.Tensor, lengths: torch.Tensor, targets: torch.Tensor) -> dict[str, float]:
    """Where the balls went round, in cm: their mean centre minus the targets' midpoint ("dx", "dy",
    "dz"), and each ball's closest approach to its nearer target in an episode, median over the
    episodes ("nearest a", "nearest b").

    Args:
        path: (T, B, 2, 3) balls a and b at each step, task frame; lengths: (B,) each episode's steps;
        targets: (2, 3) the task's targets.
    """
    steps = torch.arange(path.shape[0])[:, None]
    kept = (steps >= SETTLE_STEPS) & (steps < lengths[None])  # (T, B)
    centres = path[kept].reshape(-1, 3).double()  # both balls of every kept step
    offset = 100 * (centres.mean(0) - targets.mean(0))
    near = (path[:, :, :, None].double() - targets[None, None, None]).norm(dim=-1).amin(dim=-1)  # (T, B, 2)
    near = torch.where(kept[..., None], near, torch.inf).amin(dim=0)  # (B, 2)
    nearest = 100 * near.median(dim=0).values
    row = dict(zip(("dx", "dy", "dz"), offset.tolist(), strict=True))
    return row | {"nearest a": float(nearest[0]), "nearest b": float(nearest[1])}


def turns_near_targets(path: torch.Tensor, lengths: torch.Tensor, targets: torch.Tensor) -> dict[str, float]:
    """The pair's net turns in the palm's plane, all of them and those made with the pair's centre
    within each of ``CENTRE_SCALES`` times half the targets' separation of the targets' midpoint,
    episode mean (signs kept per episode, magnitudes averaged); and what turn shaping gated there
    would pay, in turns ("gated"): the growth of the pair's net turning made inside, less every
    shrinking of it wherever it happens (so no loop, in and out, earns anything); and what it would
    pay with the growth outside paid at the share (scale / centre offset)² instead of nothing
    ("soft", ``turn_shaping.soft``: pay falling off with the centre's distance).

    Args:
        path: (T, B, 2, 3) balls a and b at each step, task frame; lengths: (B,) each episode's steps;
        targets: (2, 3) the task's targets.
    """
    steps, batch = path.shape[:2]
    angle = torch.zeros(batch, dtype=torch.float64)
    angle_set = torch.zeros(batch, dtype=torch.bool)
    total = torch.zeros(batch, dtype=torch.float64)
    near = {scale: torch.zeros(batch, dtype=torch.float64) for scale in CENTRE_SCALES}
    gated = {scale: torch.zeros(batch, dtype=torch.float64) for scale in CENTRE_SCALES}
    soft = {scale: torch.zeros(batch, dtype=torch.float64) for scale in CENTRE_SCALES}
    for t in range(steps):
        angle, turn = pair_turn_step(path[t].double(), angle, angle_set)
        angle_set = angle_set | True
        turn = torch.where(t < lengths, turn, 0.0)
        offset = centre_offset(path[t].double(), targets)  # half target separations
        for scale in CENTRE_SCALES:
            near[scale] += torch.where(offset < scale, turn, 0.0)
            for pay, fall_off in ((gated, 0.0), (soft, 1.0)):  # the aid's pay, in turns
                share = turn_pay_share(path[t].double(), targets, scale, fall_off)
                pay[scale] += turn_shaping(total, turn, 1.0, math.inf, math.inf, share)[0]
        total += turn
    row = {"plane turns": float(total.abs().mean())}
    row |= {f"near {scale:g}x": float(value.abs().mean()) for scale, value in near.items()}
    row |= {f"gated {scale:g}x": float(value.mean()) for scale, value in gated.items()}
    return row | {f"soft {scale:g}x": float(value.mean()) for scale, value in soft.items()}


def turns_about_midpoint(path: torch.Tensor, lengths: torch.Tensor, targets: torch.Tensor) -> dict[str, float]:
    """How far each ball winds round the targets' midpoint in the palm's plane (net turns, the mean
    of the two balls, episode mean of magnitudes): what a pair carried round the targets makes, and
    nearly nothing where the pair goes round a centre farther from the midpoint than the balls are
    from their own centre.

    Args:
        path: (T, B, 2, 3) balls a and b at each step, task frame; lengths: (B,) each episode's steps;
        targets: (2, 3) the task's targets.
    """
    offset = (path.double() - targets.mean(0))[..., :2]  # (T, B, 2, 2) palm-plane offsets
    angle = torch.atan2(offset[..., 1], offset[..., 0])  # (T, B, 2)
    step = torch.remainder(angle.diff(dim=0) + math.pi, 2 * math.pi) - math.pi  # (T-1, B, 2)
    kept = torch.arange(1, path.shape[0])[:, None] < lengths[None]  # (T-1, B)
    winding = torch.where(kept[..., None], step, 0.0).sum(dim=0).mean(dim=1) / (2 * math.pi)  # (B,)
    return {"about midpoint": float(winding.abs().mean())}


def recount(checkpoint: str, episodes: int) -> tuple[str, dict[str, float]]:
    """(hand, over the episodes: their own rotations, net turns and recounted rotations per radius
    (means), where the balls went round (``path_offsets``) and the turning near the targets
    (``turns_near_targets``))."""
    model, spec = load_policy(checkpoint)
    config = for_path_metrics(spec.cpu_env_config().without_training_aids())
    config = dataclasses.replace(config, num_envs=episodes, seed=EVAL_SEED, backend="cpu", device="cpu")
    env = RotoEnv(config)
    recorder = BallPathRecorder(policy_groups(model.act_deterministic, config), len(env.balls))
    obs, _ = env.reset(seed=EVAL_SEED)
    with torch.no_grad():
        result = first_episodes(env, recorder, obs)
    env.close()
    targets = torch.tensor(geometry_of(env.robot).targets, dtype=torch.float64)
    path = torch.stack(recorder.positions).cpu()  # (steps, B, 2, 3)
    lengths = result["length"][:, 0].to(torch.int64)
    net = [pair_turns(path[: int(n), i])[0] for i, n in enumerate(lengths.tolist())]
    row = {"rotations": float(result["rotations"][:, 0].mean()), "net_turns": sum(net) / len(net)}
    for radius in RADII_CM:
        row[f"r={radius:g} cm"] = float(recounted_rotations(path, lengths, targets, radius / 100).mean())
    where = path_offsets(path, lengths, targets) | turns_near_targets(path, lengths, targets)
    return spec.env.robot, row | where | turns_about_midpoint(path, lengths, targets)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoints", nargs="+")
    parser.add_argument("--episodes", type=int, default=16)
    args = parser.parse_args()
    torch.set_num_threads(1)
    for checkpoint in args.checkpoints:
        robot, row = recount(checkpoint, args.episodes)
        shown = ", ".join(f"{name} {value:.2f}" for name, value in row.items())
        print(f"{robot}: {checkpoint} ({args.episodes} episodes, means): {shown}", flush=True)


if __name__ == "__main__":
    main()

"""The hold policy: every joint held at the default (cupped) pose, the floor any Baoding agent must beat.

It never swaps (the targets are placed so that it cannot); what it scores is the dense reward of
balls lying where they fell, and how often the hand drops them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import torch

from roto.envs.episodes import first_episodes
from roto.registry import make


def run_hold(
    task: str = "baoding",
    robot: str = "shadow",
    num_envs: int = 64,
    seed: int = 0,
    backend: str = "cpu",
    action_noise: float = 0.0,
) -> dict[str, float]:
    """One episode per env of the hold policy from the env's own starts; its return and metrics.

    ``action_noise`` > 0 adds independent N(0, action_noise²) noise to every action of every step
    (actions in [-1, 1] span each joint's range): how much of a fresh policy's exploration noise
    the hand tolerates before it drops the balls.
    """
    if action_noise < 0:
        raise ValueError(f"action_noise must be >= 0, got {action_noise}")
    env = make(task, robot=robot, num_envs=num_envs, seed=seed, backend=backend)
    hold = env.hold_action().expand(num_envs, -1).contiguous()
    noise = torch.Generator().manual_seed(seed)

    def policy(_obs: object) -> torch.Tensor:
        if action_noise == 0:
            return hold
        return hold + action_noise * torch.randn(hold.shape, generator=noise, dtype=hold.dtype)

    obs, _ = env.reset()
    result = first_episodes(env, policy, obs)
    env.close()
    stats = {
        "task": env.task.name,
        "robot": env.robot.name,
        "episodes": num_envs,
        "action_noise": action_noise,
        "mean_return": float(result["return"].mean()),
        "std_return": float(result["return"].std()),
        "mean_length": float(result["length"].mean()),
        "full_length_share": float((result["length"] == env.config.episode_steps).to(torch.float64).mean()),
    }
    stats.update({f"mean_{name}": float(result[name].mean()) for name in env.task.metric_names})
    return stats


def tolerated_noise(
    rows: Iterable[Mapping[str, object]], robot: str, share: float = 0.5, episode_steps: int = 600
) -> float:
    """The largest action noise under which ``robot``'s hold pose keeps the Baoding balls for at
    least ``share`` of an ``episode_steps`` episode on average: a property of the hand that bounds
    how much exploration noise its policy can start with before it mostly drops the balls.

    Args:
        rows: ``run_hold`` results (``benchmarks/baoding_hold.py --noise ...``: one per hand and
            noise level, with ``robot``, ``action_noise`` and ``mean_length``).
        robot: the hand.
    Raises ValueError when no row of ``robot`` keeps the balls that long (naming the noise levels
    measured).
    """
    mine = sorted((float(r["action_noise"]), float(r["mean_length"])) for r in rows if r["robot"] == robot)
    kept = [noise for noise, length in mine if length >= share * episode_steps]
    if not kept:
        raise ValueError(
            f"no measured noise level keeps {robot!r}'s balls for {share:g} of an episode; "
            f"measured (noise, mean length): {mine}"
        )
    return max(kept)

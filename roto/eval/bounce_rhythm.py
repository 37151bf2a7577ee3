"""The rhythm of a Bounce policy: how long the ball rests on the hand, how long it flies, how high.

A bounce needs ``MIN_FLIGHT_STEPS`` control steps without contact before the touch (roto.tasks.bounce),
so a 600-step episode holds at most 600 / (MIN_FLIGHT_STEPS + 1) = 100 bounces; a policy's count is
600 over its period (steps from one counted bounce to the next), and the period is the touch's
length plus the flight's. ``rhythm`` splits the period into those parts from recorded episodes;
``record_rhythm`` records them from a policy on the CPU backend.
"""

from __future__ import annotations

import itertools

import numpy as np
import torch

from roto.envs.ball_paths import BALL_GROUP, with_ball_state
from roto.envs.observations import ball_positions
from roto.envs.roto_env import RotoEnv
from roto.rl.networks import ActorCritic
from roto.rl.run_spec import RunSpec
from roto.rl.torch_threads import single_torch_thread
from roto.tasks.bounce import MIN_FLIGHT_STEPS


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """(start, length) of every maximal run of True in ``flags`` (T,) bool."""
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    return [(int(s), int(e - s)) for s, e in zip(starts, ends, strict=True)]


def _mean(values: list | np.ndarray) -> float:
    return float(np.mean(values)) if len(values) else float("nan")


def rhythm(contact: np.ndarray, bounce: np.ndarray, height: np.ndarray, lengths: np.ndarray) -> dict[str, float]:
    """Period, touch, flight and apex of the counted bounces of recorded episodes.

    Args:
        contact: (T, B) bool, ball-hand contact after each control step.
        bounce: (T, B) bool, a bounce was counted at that step (the first step of a touch).
        height: (T, B) ball centre height (m) after each step, in the task frame.
        lengths: (B,) int, steps of each env's episode (its steps from there on are not read).

    Returns:
        bounces: counted bounces per episode (mean over B); steps: episode length (mean over B);
        period_steps: mean control steps from one counted bounce to the next;
        touch_steps: mean contact steps of the touches that counted;
        flight_steps: mean steps without contact before a counted touch;
        apex_cm: mean rise of the ball (cm) over those flights, above its height when it left the hand;
        min_flight_share: share of counted flights exactly ``MIN_FLIGHT_STEPS`` long (the rule's floor);
        short_touches: touches per episode that did not count (a flight under ``MIN_FLIGHT_STEPS``).
    """
    periods, touches, flights, apexes, short, total = [], [], [], [], 0, 0
    num_envs = contact.shape[1]
    for b in range(num_envs):
        n = int(lengths[b])
        counted = set(np.flatnonzero(bounce[:n, b]).tolist())
        runs = _runs(contact[:n, b])
        periods.extend(np.diff(sorted(counted)).tolist())
        total += len(counted)
        for (prev_start, prev_len), (start, length) in itertools.pairwise(runs):
            if start not in counted:
                short += 1
                continue
            left = prev_start + prev_len  # first step without contact
            touches.append(length)
            flights.append(start - left)
            apexes.append(100.0 * float(height[left:start, b].max() - height[left - 1, b]))
    flights_arr = np.asarray(flights, dtype=np.float64)
    return {
        "bounces": total / num_envs,
        "steps": float(np.mean(lengths)),
        "period_steps": _mean(periods),
        "touch_steps": _mean(touches),
        "flight_steps": _mean(flights),
        "apex_cm": _mean(apexes),
        "min_flight_share": _mean(flights_arr == MIN_FLIGHT_STEPS),
        "short_touches": short / num_envs,
    }


@torch.no_grad()
def record_rhythm(
    model: ActorCritic, spec: RunSpec, envs: int = 16, seed: int = 1_000_000
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(contact, bounce, height), each (T, B), and lengths (B,) of the first episode of every env
    under ``model``'s deterministic policy on Bounce (CPU backend, ``spec``'s env): ``rhythm``'s
    inputs. An episode's last step (where the env starts the next one) is left out of its length."""
    if spec.env.task != "bounce":
        raise ValueError(f"the bounce rhythm needs a Bounce run (task 'bounce'), got task {spec.env.task!r}")
    if envs < 1:
        raise ValueError(f"the bounce rhythm needs envs >= 1, got {envs}")
    env = RotoEnv(with_ball_state(spec.cpu_env_config(num_envs=envs, seed=seed)))
    obs, _ = env.reset(seed=seed)
    steps = env.config.episode_steps
    contact, bounce, height = [], [], []
    lengths = np.full(envs, steps, dtype=np.int64)
    last = torch.zeros(envs, dtype=torch.int64)
    with single_torch_thread(env.device):
        for t in range(steps):
            obs, _, terminated, truncated, _ = env.step(model.act_deterministic(obs))
            done = (terminated | truncated).numpy()
            lengths[done & (lengths == steps)] = t  # the first episode's steps before this one
            count = env.task_state.bounces.clone()
            contact.append(env.task_state.prev_contact.numpy().copy())
            bounce.append((count > last).numpy())
            height.append(ball_positions(obs[BALL_GROUP], 1)[:, 0, 2].double().numpy())
            last = count
    env.close()
    return np.stack(contact), np.stack(bounce), np.stack(height), lengths

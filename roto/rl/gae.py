"""Generalised advantage estimation (pure)."""

from __future__ import annotations

import torch


def compute_gae(
    rewards: torch.Tensor,
    values: torch.Tensor,
    dones: torch.Tensor,
    last_values: torch.Tensor,
    gamma: float,
    lam: float,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Advantages and returns over a rollout.

    Args:
        rewards: (T, B) reward of each step (time-out bootstrapping, if any, already added).
        values: (T, B) V(s_t).
        dones: (T, B) bool, the episode ended at step t (terminated or truncated): nothing after it
            is bootstrapped.
        last_values: (B,) V(s_T) of the observation after the last step.
        gamma, lam: discount and GAE lambda.

    Returns:
        (advantages (T, B), returns = advantages + values (T, B)).
    """
    steps = rewards.shape[0]
    advantages = torch.zeros_like(rewards)
    running = torch.zeros_like(last_values)
    not_done = 1.0 - dones.to(rewards.dtype)
    for t in reversed(range(steps)):
        next_values = last_values if t == steps - 1 else values[t + 1]
        delta = rewards[t] + gamma * next_values * not_done[t] - values[t]
        running = delta + gamma * lam * not_done[t] * running
        advantages[t] = running
    return advantages, advantages + values

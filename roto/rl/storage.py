"""The on-policy rollout buffer and its minibatches."""

from __future__ import annotations

from collections.abc import Iterator

import torch


class RolloutBuffer:
    """T steps of B envs: observations (T, B, D), actions (T, B, n), and (T, B) scalars.

    Args:
        steps, num_envs, obs_dim, num_actions: T, B, D, n.
        device: where the buffer lives.
    """

    def __init__(self, steps: int, num_envs: int, obs_dim: int, num_actions: int, device: torch.device) -> None:
        self.steps, self.num_envs = steps, num_envs
        shape = (steps, num_envs)
        self.obs = torch.zeros(*shape, obs_dim, device=device)
        self.actions = torch.zeros(*shape, num_actions, device=device)
        self.log_probs = torch.zeros(shape, device=device)
        self.values = torch.zeros(shape, device=device)
        self.rewards = torch.zeros(shape, device=device)
        self.dones = torch.zeros(shape, dtype=torch.bool, device=device)
        self.advantages = torch.zeros(shape, device=device)
        self.returns = torch.zeros(shape, device=device)
        self.step = 0

    def add(
        self,
        obs: torch.Tensor,
        actions: torch.Tensor,
        log_probs: torch.Tensor,
        values: torch.Tensor,
        rewards: torch.Tensor,
        dones: torch.Tensor,
    ) -> None:
        """Store one step: obs (B, D), actions (B, n), the rest (B,)."""
        if self.step >= self.steps:
            raise RuntimeError(f"rollout buffer is full ({self.steps} steps); call clear() first")
        t = self.step
        self.obs[t], self.actions[t], self.log_probs[t] = obs, actions, log_probs
        self.values[t], self.rewards[t], self.dones[t] = values, rewards, dones
        self.step += 1

    def clear(self) -> None:
        """Start a new rollout."""
        self.step = 0

    def minibatches(self, num_minibatches: int, generator: torch.Generator) -> Iterator[dict[str, torch.Tensor]]:
        """One epoch: a random permutation of the T·B samples split into ``num_minibatches`` parts.

        Every sample appears in exactly one minibatch (the last parts take the remainder).
        """
        total = self.steps * self.num_envs
        if not 1 <= num_minibatches <= total:
            raise ValueError(f"num_minibatches must be in [1, {total}], got {num_minibatches}")
        flat = {
            "obs": self.obs.flatten(0, 1),
            "actions": self.actions.flatten(0, 1),
            "log_probs": self.log_probs.flatten(0, 1),
            "values": self.values.flatten(0, 1),
            "advantages": self.advantages.flatten(0, 1),
            "returns": self.returns.flatten(0, 1),
        }
        order = torch.randperm(total, generator=generator, device=generator.device).to(self.obs.device)
        for part in torch.tensor_split(order, num_minibatches):
            yield {name: value[part] for name, value in flat.items()}

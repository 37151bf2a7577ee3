"""The on-policy rollout buffer: observation groups kept apart, and its minibatches."""

from __future__ import annotations

from collections.abc import Iterator, Mapping

import torch


class RolloutBuffer:
    """T steps of B envs: each observation group (T, B, D_g), actions (T, B, n), and (T, B) scalars.

    Args:
        steps, num_envs: T, B.
        group_sizes: {group: stacked size D_g} of every group to store.
        num_actions: n.
        device: where the buffer lives.
    """

    def __init__(
        self, steps: int, num_envs: int, group_sizes: Mapping[str, int], num_actions: int, device: torch.device
    ) -> None:
        self.steps, self.num_envs = steps, num_envs
        shape = (steps, num_envs)
        self.obs = {group: torch.zeros(*shape, size, device=device) for group, size in group_sizes.items()}
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
        obs: Mapping[str, torch.Tensor],
        actions: torch.Tensor,
        log_probs: torch.Tensor,
        values: torch.Tensor,
        rewards: torch.Tensor,
        dones: torch.Tensor,
    ) -> None:
        """Store one step: obs {group: (B, D_g)} (the stored groups), actions (B, n), the rest (B,)."""
        if self.step >= self.steps:
            raise RuntimeError(f"rollout buffer is full ({self.steps} steps); call clear() first")
        t = self.step
        for group, stored in self.obs.items():
            stored[t] = obs[group]
        self.actions[t], self.log_probs[t] = actions, log_probs
        self.values[t], self.rewards[t], self.dones[t] = values, rewards, dones
        self.step += 1

    def clear(self) -> None:
        """Start a new rollout."""
        self.step = 0

    def flat_obs(self) -> dict[str, torch.Tensor]:
        """Every stored observation, {group: (T·B, D_g)}."""
        return {group: value.flatten(0, 1) for group, value in self.obs.items()}

    def minibatches(self, num_minibatches: int, generator: torch.Generator) -> Iterator[dict]:
        """One epoch: a random permutation of the T·B samples split into ``num_minibatches`` parts.

        Every sample appears in exactly one minibatch (the last parts take the remainder). Each
        minibatch is {"obs": {group: (N, D_g)}, "actions": (N, n), and (N,) "log_probs", "values",
        "advantages", "returns"}.
        """
        total = self.steps * self.num_envs
        if not 1 <= num_minibatches <= total:
            raise ValueError(f"num_minibatches must be in [1, {total}], got {num_minibatches}")
        obs = self.flat_obs()
        flat = {
            "actions": self.actions.flatten(0, 1),
            "log_probs": self.log_probs.flatten(0, 1),
            "values": self.values.flatten(0, 1),
            "advantages": self.advantages.flatten(0, 1),
            "returns": self.returns.flatten(0, 1),
        }
        order = torch.randperm(total, generator=generator, device=generator.device).to(self.actions.device)
        for part in torch.tensor_split(order, num_minibatches):
            batch: dict = {name: value[part] for name, value in flat.items()}
            batch["obs"] = {group: value[part] for group, value in obs.items()}
            yield batch

"""The actor-critic of roto's PPO (docs/spec.md §7), reading named observation groups.

The actor reads its groups through one encoder (Linear -> LayerNorm -> ELU per layer) that the
auxiliary losses also train. The critic either shares that encoder (roto's agent) or, when it reads
other groups (a privileged critic), has an encoder of its own, so nothing the actor cannot see ever
enters the actor's network.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

import torch
from torch import nn

from roto.rl.normalizers import RunningStandardScaler

LOG_STD_MIN, LOG_STD_MAX = -20.0, 2.0
HOLD_START_GAIN = 0.01
"""Scale of the action layer's initial weights when a policy starts at a given action
(``network.start_at_hold``): CleanRL's and RSL-RL's small output init, which keeps the mean action
within about 0.01 of the start action for inputs of unit scale."""

Obs = Mapping[str, torch.Tensor]
"""Observation groups: {group name: (N, stacked size)}."""


def mlp(sizes: Sequence[int], layer_norm: bool = True) -> nn.Sequential:
    """Linear -> (LayerNorm) -> ELU for each consecutive pair in ``sizes``."""
    layers: list[nn.Module] = []
    for n_in, n_out in itertools.pairwise(sizes):
        layers.append(nn.Linear(n_in, n_out))
        if layer_norm:
            layers.append(nn.LayerNorm(n_out))
        layers.append(nn.ELU())
    return nn.Sequential(*layers)


def concat_groups(obs: Obs, groups: Sequence[str]) -> torch.Tensor:
    """(N, sum of sizes) float32: ``groups`` of ``obs`` concatenated in the order given."""
    return torch.cat([obs[group].to(torch.float32) for group in groups], dim=-1)


class GroupInput(nn.Module):
    """Concatenates named groups into one input and standardises it with running statistics.

    Args:
        groups: group names, in concatenation order.
        sizes: {group: stacked size}; must hold every name in ``groups``.
        normalize: keep a ``RunningStandardScaler`` (clip ±5) in this module.
    """

    def __init__(self, groups: Sequence[str], sizes: Mapping[str, int], normalize: bool = True) -> None:
        super().__init__()
        missing = [g for g in groups if g not in sizes]
        if missing:
            raise ValueError(f"observation groups {missing} are not provided; available: {list(sizes)}")
        self.groups = tuple(groups)
        self.width = sum(sizes[g] for g in self.groups)
        self.scaler = RunningStandardScaler(self.width, clip=5.0) if normalize else None

    def forward(self, obs: Obs) -> torch.Tensor:
        """Standardised input (N, width)."""
        x = concat_groups(obs, self.groups)
        return x if self.scaler is None else self.scaler(x)

    @torch.no_grad()
    def update(self, obs: Obs) -> None:
        """Fold a batch of observations ((..., size) per group) into the running statistics."""
        if self.scaler is not None:
            self.scaler.update(concat_groups(obs, self.groups))


class ActorCritic(nn.Module):
    """Gaussian policy with a state-independent log-std and a value function over observation groups.

    Args:
        sizes: {group: stacked size} of every group the env returns.
        num_actions: action size n.
        actor_groups: groups the actor's encoder reads.
        critic_groups: groups the critic reads (None or equal to ``actor_groups``: shared encoder).
        encoder: hidden sizes of the encoder(s).
        policy_head, value_head: hidden sizes of the heads (Linear -> ELU), then a linear output.
        init_log_std: initial log standard deviation of every action dimension.
        max_log_std: upper bound of the log standard deviation (clamped in the forward pass).
        project_log_std: ``after_optimizer_step`` puts the log-std parameter back inside its bounds.
        obs_normalization: standardise each encoder's input with running statistics kept here.
    """

    def __init__(
        self,
        sizes: Mapping[str, int],
        num_actions: int,
        *,
        actor_groups: Sequence[str],
        critic_groups: Sequence[str] | None = None,
        encoder: Sequence[int] = (512, 256),
        policy_head: Sequence[int] = (128, 64),
        value_head: Sequence[int] = (128, 64),
        init_log_std: float = 0.0,
        max_log_std: float = LOG_STD_MAX,
        project_log_std: bool = False,
        obs_normalization: bool = True,
    ) -> None:
        super().__init__()
        self.num_actions = int(num_actions)
        self.actor_sizes = {group: int(sizes[group]) for group in actor_groups}
        self.actor_input = GroupInput(actor_groups, sizes, obs_normalization)
        self.encoder = mlp([self.actor_input.width, *encoder])
        self.latent_width = encoder[-1] if encoder else self.actor_input.width
        self.policy_body = mlp([self.latent_width, *policy_head], layer_norm=False)
        self.policy_mean = nn.Linear(policy_head[-1] if policy_head else self.latent_width, num_actions)
        if not max_log_std > LOG_STD_MIN:
            raise ValueError(f"network.max_log_std must be above {LOG_STD_MIN}, got {max_log_std}")
        self.max_log_std = float(max_log_std)
        self.project_log_std = bool(project_log_std)
        self.log_std = nn.Parameter(torch.full((num_actions,), float(init_log_std)))
        self.critic_input: GroupInput | None = None
        self.critic_encoder: nn.Sequential | None = None
        if critic_groups is not None and tuple(critic_groups) != tuple(actor_groups):
            self.critic_input = GroupInput(critic_groups, sizes, obs_normalization)
            self.critic_encoder = mlp([self.critic_input.width, *encoder])
        self.value_body = mlp([self.latent_width, *value_head], layer_norm=False)
        self.value_out = nn.Linear(value_head[-1] if value_head else self.latent_width, 1)

    @property
    def actor_groups(self) -> tuple[str, ...]:
        """The groups the policy reads."""
        return self.actor_input.groups

    @property
    def critic_groups(self) -> tuple[str, ...]:
        """The groups the value function reads."""
        return self.actor_input.groups if self.critic_input is None else self.critic_input.groups

    def encode(self, obs: Obs) -> torch.Tensor:
        """The actor's latent (N, W): what the policy head and the auxiliary losses read."""
        return self.encoder(self.actor_input(obs))

    def value(self, obs: Obs, latent: torch.Tensor | None = None) -> torch.Tensor:
        """V (N,) in the value head's units; ``latent``: the actor's, reused when the encoder is shared."""
        if self.critic_encoder is not None:
            latent = self.critic_encoder(self.critic_input(obs))
        elif latent is None:
            latent = self.encode(obs)
        return self.value_out(self.value_body(latent)).squeeze(-1)

    def clamped_log_std(self) -> torch.Tensor:
        """(n,) the policy's log standard deviation within [LOG_STD_MIN, max_log_std]."""
        return self.log_std.clamp(LOG_STD_MIN, self.max_log_std)

    @torch.no_grad()
    def after_optimizer_step(self) -> None:
        """With ``project_log_std``, the log-std parameter back inside [LOG_STD_MIN, max_log_std]: at
        the bound the forward pass's clamp passes its gradient on, past it none."""
        if self.project_log_std:
            self.log_std.clamp_(LOG_STD_MIN, self.max_log_std)

    def forward(self, obs: Obs) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
        """(action mean (N, n), log-std (n,), value (N,), actor latent (N, W))."""
        z = self.encode(obs)
        mean = self.policy_mean(self.policy_body(z))
        return mean, self.clamped_log_std(), self.value(obs, z), z

    @torch.no_grad()
    def start_mean_at(self, action: torch.Tensor, gain: float = HOLD_START_GAIN) -> None:
        """Make the mean action start at ``action`` (n,) for every observation, up to ``gain``: the
        action layer's weights scaled by ``gain``, its bias set to ``action``. Consumes no random
        numbers, so the rest of a seeded run draws what it would have drawn."""
        if action.shape != (self.num_actions,):
            raise ValueError(f"start action must have shape ({self.num_actions},), got {tuple(action.shape)}")
        if not 0 <= gain <= 1:
            raise ValueError(f"gain must be in [0, 1], got {gain}")
        self.policy_mean.weight.mul_(gain)
        self.policy_mean.bias.copy_(action)

    @torch.no_grad()
    def act_deterministic(self, obs: Obs) -> torch.Tensor:
        """The mean action (N, n): what evaluation runs. Reads only the actor's groups."""
        return self.policy_mean(self.policy_body(self.encode(obs)))

    def update_normalizers(self, obs: Obs) -> None:
        """Fold a batch of observations into the input statistics of the actor (and critic)."""
        self.actor_input.update(obs)
        if self.critic_input is not None:
            self.critic_input.update(obs)

"""The actor-critic of roto's PPO (SPEC §7): shared encoder, policy and value heads."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import torch
from torch import nn

from roto.rl.normalizers import RunningStandardScaler

LOG_STD_MIN, LOG_STD_MAX = -20.0, 2.0


def mlp(sizes: Sequence[int], layer_norm: bool = True) -> nn.Sequential:
    """Linear -> (LayerNorm) -> ELU for each consecutive pair in ``sizes``."""
    layers: list[nn.Module] = []
    for n_in, n_out in itertools.pairwise(sizes):
        layers.append(nn.Linear(n_in, n_out))
        if layer_norm:
            layers.append(nn.LayerNorm(n_out))
        layers.append(nn.ELU())
    return nn.Sequential(*layers)


class ActorCritic(nn.Module):
    """Shared encoder, Gaussian policy with a state-independent log-std, and a value head.

    Args:
        obs_dim: size D of the flat (stacked) observation.
        num_actions: action size n.
        encoder: hidden sizes of the shared encoder (each Linear -> LayerNorm -> ELU).
        policy_head, value_head: hidden sizes of the heads (Linear -> ELU), then a linear output.
        init_log_std: initial log standard deviation of every action dimension.
        obs_normalization: standardise observations with running statistics kept in this module.
    """

    def __init__(
        self,
        obs_dim: int,
        num_actions: int,
        encoder: Sequence[int] = (512, 256),
        policy_head: Sequence[int] = (128, 64),
        value_head: Sequence[int] = (128, 64),
        init_log_std: float = 0.0,
        obs_normalization: bool = True,
    ) -> None:
        super().__init__()
        self.obs_scaler = RunningStandardScaler(obs_dim, clip=5.0) if obs_normalization else None
        self.encoder = mlp([obs_dim, *encoder])
        width = encoder[-1] if encoder else obs_dim
        self.policy_body = mlp([width, *policy_head], layer_norm=False)
        self.policy_mean = nn.Linear(policy_head[-1] if policy_head else width, num_actions)
        self.value_body = mlp([width, *value_head], layer_norm=False)
        self.value_out = nn.Linear(value_head[-1] if value_head else width, 1)
        self.log_std = nn.Parameter(torch.full((num_actions,), float(init_log_std)))

    def encode(self, obs: torch.Tensor) -> torch.Tensor:
        """Latent (N, W) of flat observations (N, D)."""
        if self.obs_scaler is not None:
            obs = self.obs_scaler(obs)
        return self.encoder(obs)

    def forward(self, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """(action mean (N, n), log-std (n,), value (N,)) for observations (N, D)."""
        z = self.encode(obs)
        mean = self.policy_mean(self.policy_body(z))
        value = self.value_out(self.value_body(z)).squeeze(-1)
        return mean, self.log_std.clamp(LOG_STD_MIN, LOG_STD_MAX), value

    def distribution(self, obs: torch.Tensor) -> tuple[torch.distributions.Normal, torch.Tensor]:
        """(Normal over actions, value (N,))."""
        mean, log_std, value = self(obs)
        return torch.distributions.Normal(mean, log_std.exp().expand_as(mean)), value

    @torch.no_grad()
    def act_deterministic(self, obs: torch.Tensor) -> torch.Tensor:
        """The mean action (N, n): what evaluation runs."""
        return self.policy_mean(self.policy_body(self.encode(obs)))

"""The one interface every auxiliary loss implements (docs/training.md, "Auxiliary losses")."""

from __future__ import annotations

from typing import Any, Protocol

import torch
from torch import nn

from roto.rl.networks import ActorCritic
from roto.rl.ssl.configs import AuxLossConfig
from roto.rl.storage import RolloutBuffer


class AuxLoss(Protocol):
    """A self-supervised loss on the actor's encoder, added to PPO's loss with its own weight.

    The update calls, per PPO update: ``prepare`` once; then in each of the first
    max(1, floor(epochs · epoch_ratio)) epochs, for PPO minibatch i, ``loss`` with aux batch i
    (from ``batches``), one backward of the weighted sum of every term, the PPO optimiser's step,
    then ``optimizer.step()`` and ``after_step``.
    """

    name: str
    config: AuxLossConfig
    heads: nn.Module
    """The loss's own trainable modules (decoder, latent model, projector)."""
    optimizer: torch.optim.Optimizer
    """Adam over ``heads`` and the actor's encoder, at ``config.lr``."""

    def prepare(self, buffer: RolloutBuffer, num_minibatches: int, generator: torch.Generator) -> list[Any]:
        """Once per update, before the epochs: one aux batch per PPO minibatch (None: use PPO's)."""
        ...

    def loss(
        self, model: ActorCritic, batch: dict, latent: torch.Tensor, aux_batch: Any
    ) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
        """(scalar loss, detached metrics) on PPO minibatch ``batch`` (its actor latent ``latent``)."""
        ...

    def after_step(self, model: ActorCritic) -> None:
        """After the optimisers' steps (e.g. move an EMA target encoder)."""
        ...

    def state_dict(self) -> dict[str, Any]:
        """Heads, optimiser and any other state, for exact resume."""
        ...

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore ``state_dict``'s output."""
        ...


def aux_epochs(epochs: int, epoch_ratio: float) -> int:
    """Epochs of an update that use an auxiliary loss: max(1, floor(epochs · ratio)) (roto's rule)."""
    return max(1, int(epochs * epoch_ratio))

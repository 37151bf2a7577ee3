"""Reconstruction of stacked observation groups from the actor's latent (docs/spec.md §7).

``tactile_reconstruction`` decodes the stacked touch bits; ``full_reconstruction`` also the stacked
proprioception. Touch is scored with a binary cross-entropy whose positive bits are weighted by
how rare they are in the batch; every other group with a mean squared error.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import torch
import torch.nn.functional as F
from torch import nn

from roto.rl.networks import ActorCritic, mlp
from roto.rl.ssl.configs import ReconstructionConfig
from roto.rl.storage import RolloutBuffer

MIN_BIT_RATE = 1e-6
MAX_POS_WEIGHT = 1e4


def rare_bit_bce(logits: torch.Tensor, bits: torch.Tensor) -> torch.Tensor:
    """Binary cross-entropy with logits, each bit's positives weighted by (1 - p) / p.

    p is the bit's mean over the batch, at least 1e-6; the weight is at most 1e4. Averaged over
    every element.

    Args:
        logits, bits: (N, K); bits in {0, 1}.
    """
    rate = bits.mean(dim=0).clamp_min(MIN_BIT_RATE)
    pos_weight = ((1.0 - rate) / rate).clamp_max(MAX_POS_WEIGHT)
    return F.binary_cross_entropy_with_logits(logits, bits, pos_weight=pos_weight)


class Reconstruction:
    """Decoder latent -> stacked target groups, trained with the encoder.

    Args:
        name: the loss's name (its key under ``ssl``).
        config: weight, lr, decoder sizes, target groups.
        model: the actor-critic whose encoder it trains.
        sizes: {group: stacked size} of every group the env returns.
        touch: the env's touch signal; ``binary`` bits are decoded with a weighted BCE, ``force``
            values (log-scaled forces) with an MSE.
    """

    def __init__(
        self,
        name: str,
        config: ReconstructionConfig,
        model: ActorCritic,
        sizes: Mapping[str, int],
        touch: str = "binary",
    ) -> None:
        missing = [g for g in config.targets if g not in sizes]
        if missing:
            raise ValueError(f"ssl.{name}.targets: groups {missing} are not provided; available: {list(sizes)}")
        self.name, self.config = name, config
        self.binary_tactile = touch == "binary"
        self.widths = [sizes[g] for g in config.targets]
        hidden = config.decoder[-1] if config.decoder else model.latent_width
        self.heads = nn.Sequential(mlp([model.latent_width, *config.decoder]), nn.Linear(hidden, sum(self.widths)))
        self.heads.to(next(model.parameters()).device)
        self.optimizer = torch.optim.Adam([*self.heads.parameters(), *model.encoder.parameters()], lr=config.lr)

    def prepare(self, buffer: RolloutBuffer, num_minibatches: int, generator: torch.Generator) -> list[Any]:
        """Reconstruction reads PPO's own minibatches: no batches of its own."""
        return [None] * num_minibatches

    def loss(
        self, model: ActorCritic, batch: dict, latent: torch.Tensor, aux_batch: Any
    ) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
        """Sum over targets of BCE (binary tactile) or MSE (others) of the decoded ``latent`` (N, W)."""
        predictions = self.heads(latent).split(self.widths, dim=-1)
        terms = {}
        for group, prediction in zip(self.config.targets, predictions, strict=True):
            target = batch["obs"][group].to(prediction.dtype)
            if group == "tactile" and self.binary_tactile:
                terms[group] = rare_bit_bce(prediction, target)
            else:
                terms[group] = F.mse_loss(prediction, target)
        total = sum(terms.values(), torch.zeros((), device=latent.device))
        return total, {group: value.detach() for group, value in terms.items()}

    def after_step(self, model: ActorCritic) -> None:
        """Nothing to do."""

    def state_dict(self) -> dict[str, Any]:
        """Decoder and optimiser."""
        return {"heads": self.heads.state_dict(), "optimizer": self.optimizer.state_dict()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore ``state_dict``'s output."""
        self.heads.load_state_dict(state["heads"])
        self.optimizer.load_state_dict(state["optimizer"])

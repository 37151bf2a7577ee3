"""Forward dynamics in latent space (docs/spec.md §7), on the sequences of the current rollout.

For a sequence of observations o_1..o_L and actions a_1..a_L (no episode end inside), the online
encoder gives z_t = f(o_t), a residual latent model predicts z'_{t+1} = z_t + g([z_t, a_t]), and a
projector p maps the prediction into the space of an EMA copy of the encoder f̄:

    loss = Σ_{t=1}^{L-1} mean over batch and latent dims of (p(z'_{t+1}) - f̄(o_{t+1}))²

Every prediction starts from the true z_t (one step ahead, no open-loop rollout). f̄ gets no
gradient and follows f by f̄ <- (1 - tau) f̄ + tau f after every optimiser step.
"""

from __future__ import annotations

import copy
from typing import Any

import torch
from torch import nn

from roto.rl.networks import ActorCritic, mlp
from roto.rl.ssl.configs import ForwardDynamicsConfig
from roto.rl.ssl.sequences import sequence_windows, split_windows
from roto.rl.storage import RolloutBuffer


class ResidualLatentModel(nn.Module):
    """g(z, a) = z + MLP([z, a]): hidden layers Linear -> ELU, then a linear layer to the latent width."""

    def __init__(self, latent_width: int, num_actions: int, hidden: tuple[int, ...]) -> None:
        super().__init__()
        last = hidden[-1] if hidden else latent_width + num_actions
        self.net = nn.Sequential(
            mlp([latent_width + num_actions, *hidden], layer_norm=False), nn.Linear(last, latent_width)
        )

    def forward(self, latent: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        """Next latent (..., W) from latent (..., W) and action (..., n)."""
        return latent + self.net(torch.cat([latent, action], dim=-1))


def forward_dynamics_loss(prediction: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Σ over time of the mean squared error over batch and latent dims.

    Args:
        prediction, target: (S, L - 1, W).
    """
    return (prediction - target).square().mean(dim=(0, 2)).sum()


class ForwardDynamics:
    """Forward dynamics on every valid sequence of the rollout just collected.

    Args:
        name: the loss's name (its key under ``ssl``).
        config: weight, lr, L, tau, latent model and projector sizes.
        model: the actor-critic whose encoder it trains.
        num_actions: n.
    """

    def __init__(self, name: str, config: ForwardDynamicsConfig, model: ActorCritic, num_actions: int) -> None:
        self.name, self.config = name, config
        width = model.latent_width
        last = config.projector[-1] if config.projector else width
        projector = nn.Sequential(mlp([width, *config.projector], layer_norm=False), nn.Linear(last, width))
        self.heads = nn.ModuleDict(
            {"latent_model": ResidualLatentModel(width, num_actions, config.latent_model), "projector": projector}
        )
        self.heads.to(next(model.parameters()).device)
        self.target_encoder = copy.deepcopy(model.encoder).requires_grad_(False)
        self.optimizer = torch.optim.Adam([*self.heads.parameters(), *model.encoder.parameters()], lr=config.lr)

    def windows(self, buffer: RolloutBuffer) -> dict:
        """The sequences this update trains on: every valid window of the rollout."""
        return sequence_windows(buffer.obs, buffer.actions, buffer.dones, self.config.seq_length)

    def prepare(self, buffer: RolloutBuffer, num_minibatches: int, generator: torch.Generator) -> list[Any]:
        """The update's sequences (at most ``max_sequences``), shuffled once into one batch per PPO minibatch."""
        return split_windows(self.windows(buffer), num_minibatches, generator, self.config.max_sequences)

    def loss(
        self, model: ActorCritic, batch: dict, latent: torch.Tensor, aux_batch: Any
    ) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
        """The forward-dynamics loss of ``aux_batch`` ({"obs": {group: (S, L, D)}, "actions": (S, L, n)})."""
        actions = aux_batch["actions"]
        count, length = actions.shape[:2]
        if count == 0:  # no sequence without an episode end in this rollout
            zero = latent.sum() * 0.0
            return zero, {"latent_mse": zero.detach()}
        flat_obs = {g: v.flatten(0, 1) for g, v in aux_batch["obs"].items()}
        inputs = model.actor_input(flat_obs)
        z = model.encoder(inputs).unflatten(0, (count, length))
        with torch.no_grad():
            target = self.target_encoder(inputs).unflatten(0, (count, length))[:, 1:]
        predicted = self.heads["latent_model"](z[:, :-1], actions[:, :-1])
        loss = forward_dynamics_loss(self.heads["projector"](predicted), target)
        return loss, {"latent_mse": loss.detach() / (length - 1)}

    @torch.no_grad()
    def after_step(self, model: ActorCritic) -> None:
        """Move the target encoder towards the online one: f̄ <- (1 - tau) f̄ + tau f."""
        for target, online in zip(self.target_encoder.parameters(), model.encoder.parameters(), strict=True):
            target.lerp_(online, self.config.tau)

    def state_dict(self) -> dict[str, Any]:
        """Heads, target encoder and optimiser."""
        return {
            "heads": self.heads.state_dict(),
            "target_encoder": self.target_encoder.state_dict(),
            "optimizer": self.optimizer.state_dict(),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore ``state_dict``'s output."""
        self.heads.load_state_dict(state["heads"])
        self.target_encoder.load_state_dict(state["target_encoder"])
        self.optimizer.load_state_dict(state["optimizer"])

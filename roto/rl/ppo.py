"""One PPO update over a filled rollout buffer (SPEC §7)."""

from __future__ import annotations

import torch
from torch import nn

from roto.rl.config import PPOConfig
from roto.rl.gae import compute_gae
from roto.rl.losses import kl_adaptive_lr, ppo_loss
from roto.rl.networks import ActorCritic
from roto.rl.normalizers import RunningStandardScaler
from roto.rl.storage import RolloutBuffer


def explained_variance(prediction: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """1 - Var(target - prediction) / Var(target) over all elements (nan if the target is constant)."""
    var = target.var()
    return 1.0 - (target - prediction).var() / var if var > 0 else torch.tensor(float("nan"))


class PPO:
    """The learner: actor-critic, Adam, optional value-target scaler and KL-adaptive learning rate."""

    def __init__(self, model: ActorCritic, config: PPOConfig) -> None:
        self.model, self.config = model, config
        self.optimizer = torch.optim.Adam(model.parameters(), lr=config.lr)
        self.lr = config.lr
        self.value_scaler = RunningStandardScaler(1, clip=None) if config.value_normalization else None

    # -------------------------------------------------------------- values in return units

    def values(self, normalised: torch.Tensor) -> torch.Tensor:
        """Value-head output (normalised units) -> return units."""
        if self.value_scaler is None:
            return normalised
        return self.value_scaler.inverse(normalised.unsqueeze(-1)).squeeze(-1)

    def _normalise(self, values: torch.Tensor) -> torch.Tensor:
        if self.value_scaler is None:
            return values
        return self.value_scaler(values.unsqueeze(-1)).squeeze(-1)

    # ------------------------------------------------------------------------- the update

    def finish_rollout(self, buffer: RolloutBuffer, last_values: torch.Tensor) -> None:
        """GAE in return units, then store advantages (normalised) and value targets in head units.

        ``buffer.values`` holds return-unit values from the rollout; ``last_values`` (B,) too.
        """
        c = self.config
        advantages, returns = compute_gae(buffer.rewards, buffer.values, buffer.dones, last_values, c.gamma, c.lam)
        if self.value_scaler is not None:
            self.value_scaler.update(returns.reshape(-1, 1))
        buffer.returns = self._normalise(returns)
        buffer.values = self._normalise(buffer.values)
        buffer.advantages = (advantages - advantages.mean()) / (advantages.std() + 1e-8)

    def update(self, buffer: RolloutBuffer, generator: torch.Generator) -> dict[str, float]:
        """``epochs`` passes of minibatch SGD on the clipped PPO loss; returns mean diagnostics."""
        c = self.config
        sums: dict[str, torch.Tensor] = {}
        count = 0
        for _ in range(c.epochs):
            epoch_kl = []
            for batch in buffer.minibatches(c.minibatches, generator):
                dist, value = self.model.distribution(batch["obs"])
                log_prob = dist.log_prob(batch["actions"]).sum(-1)
                entropy = dist.entropy().sum(-1)
                loss, metrics = ppo_loss(
                    log_prob,
                    batch["log_probs"],
                    batch["advantages"],
                    value,
                    batch["values"],
                    batch["returns"],
                    entropy,
                    c.ratio_clip,
                    c.value_clip,
                    c.value_coef,
                    c.entropy_coef,
                )
                self.optimizer.zero_grad(set_to_none=True)
                loss.backward()
                metrics["grad_norm"] = nn.utils.clip_grad_norm_(self.model.parameters(), c.max_grad_norm)
                self.optimizer.step()
                epoch_kl.append(metrics["approx_kl"])
                for name, value_ in metrics.items():
                    sums[name] = sums.get(name, 0.0) + value_.detach()
                count += 1
            if c.kl_adaptive:
                self.lr = kl_adaptive_lr(
                    self.lr, float(torch.stack(epoch_kl).mean()), c.kl_target, c.kl_factor, c.lr_min, c.lr_max
                )
                for group in self.optimizer.param_groups:
                    group["lr"] = self.lr
        out = {name: float(total / count) for name, total in sums.items()}
        out["explained_variance"] = float(explained_variance(buffer.values, buffer.returns))
        out["action_std"] = float(self.model.log_std.detach().clamp(-20, 2).exp().mean())
        out["lr"] = self.lr
        return out

    def state_dict(self) -> dict:
        """Optimiser, learning rate and value scaler."""
        return {
            "optimizer": self.optimizer.state_dict(),
            "lr": self.lr,
            "value_scaler": None if self.value_scaler is None else self.value_scaler.state_dict(),
        }

    def load_state_dict(self, state: dict) -> None:
        """Restore ``state_dict``'s output."""
        self.optimizer.load_state_dict(state["optimizer"])
        self.lr = float(state["lr"])
        if self.value_scaler is not None:
            self.value_scaler.load_state_dict(state["value_scaler"])

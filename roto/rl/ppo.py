"""roto's PPO (docs/spec.md §7): the algorithm owns its transitions, returns and update.

The runner calls, per rollout step, ``act(obs)`` then ``process_step(...)`` with what the env
returned; after the rollout ``compute_returns(next_obs)`` and ``update()``. The update minimises a
weighted sum of named loss terms (surrogate, value, entropy and each auxiliary loss), each logged
as ``loss/<name>``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

import torch
from torch import nn

from roto.rl.config import PPOConfig
from roto.rl.gae import compute_gae
from roto.rl.graphed_call import GraphedCall
from roto.rl.graphed_step import GraphedMinibatchStep
from roto.rl.losses import kl_adaptive_lr, ppo_terms, weighted_sum
from roto.rl.networks import ActorCritic, Obs
from roto.rl.normalizers import RunningStandardScaler
from roto.rl.ssl import AuxLoss, aux_epochs
from roto.rl.storage import RolloutBuffer


def explained_variance(prediction: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """1 - Var(target - prediction) / Var(target) over all elements (nan if the target is constant)."""
    var = target.var()
    return 1.0 - (target - prediction).var() / var if var > 0 else torch.tensor(float("nan"))


def check_graphable(config: PPOConfig, storage: RolloutBuffer, aux_losses: list[AuxLoss]) -> None:
    """Raise ValueError unless ``ppo.cuda_graph`` can run: no auxiliary losses, no bfloat16 update,
    minibatches of one size, a CUDA device."""
    if config.bf16_update:
        raise ValueError("ppo.cuda_graph=true does not graph the bfloat16 update yet; set ppo.bf16_update=false")
    if aux_losses:
        names = [aux.name for aux in aux_losses]
        raise ValueError(f"ppo.cuda_graph=true does not graph auxiliary losses yet; set it false or drop ssl: {names}")
    samples = storage.steps * storage.num_envs
    if samples % config.minibatches:
        raise ValueError(
            f"ppo.cuda_graph=true needs minibatches of one size: ppo.rollouts x num_envs = {samples} "
            f"is not divisible by ppo.minibatches={config.minibatches}"
        )
    require_cuda("ppo.cuda_graph", storage.values.device)


def require_cuda(setting: str, device: torch.device) -> None:
    """Raise ValueError naming ``setting`` unless the envs (and so the learner) are on a CUDA device."""
    if device.type != "cuda":
        raise ValueError(f"{setting}=true needs the envs on a CUDA device, got device={str(device)!r}")


@contextlib.contextmanager
def tf32_matmuls(enabled: bool) -> Iterator[None]:
    """Within: CUDA matrix products may use TF32 if ``enabled`` (or if they already could)."""
    saved = torch.backends.cuda.matmul.allow_tf32
    torch.backends.cuda.matmul.allow_tf32 = saved or enabled
    try:
        yield
    finally:
        torch.backends.cuda.matmul.allow_tf32 = saved


class PPO:
    """The learner: actor-critic, Adam, value-target scaler, KL-adaptive lr and auxiliary losses.

    Args:
        model: the actor-critic.
        config: PPO hyperparameters.
        storage: the rollout buffer ``process_step`` fills.
        generator: draws actions and minibatch permutations (its state is part of ``state_dict``).
        aux_losses: auxiliary losses trained with PPO's update (none for plain PPO).
    """

    def __init__(
        self,
        model: ActorCritic,
        config: PPOConfig,
        storage: RolloutBuffer,
        generator: torch.Generator,
        aux_losses: list[AuxLoss] | None = None,
    ) -> None:
        self.model, self.config, self.storage, self.generator = model, config, storage, generator
        self.aux_losses = list(aux_losses or [])
        self.lr = config.lr
        self._graphed: GraphedMinibatchStep | None = None
        # the forward pass and loss terms, compiled into fused kernels with ``compile_update``
        self._ppo_loss = torch.compile(self._ppo_terms, dynamic=False) if config.compile_update else self._ppo_terms
        fused = True if config.fused_adam else None  # None: PyTorch picks its default implementation
        if config.cuda_graph:
            check_graphable(config, storage, self.aux_losses)
            # a KL-adaptive lr must be a device tensor the graph reads, changed in place
            lr = torch.tensor(config.lr, device=storage.values.device) if config.kl_adaptive else config.lr
            self.optimizer = torch.optim.Adam(model.parameters(), lr=lr, capturable=True, fused=fused)
            self._graphed = GraphedMinibatchStep(lambda batch: self._minibatch_step(batch, []), model, self.optimizer)
        else:
            self.optimizer = torch.optim.Adam(model.parameters(), lr=config.lr, fused=fused)
        self.value_scaler = None
        if config.value_normalization:
            self.value_scaler = RunningStandardScaler(1, clip=None).to(storage.values.device)
        self._graphed_sample: GraphedCall | None = None
        if config.cuda_graph_rollout:
            require_cuda("ppo.cuda_graph_rollout", storage.values.device)
            self._graphed_sample = GraphedCall(self._sample)
        self._step: dict[str, Any] = {}

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

    # ------------------------------------------------------------------------ transitions

    @torch.no_grad()
    def act(self, obs: Obs) -> torch.Tensor:
        """Sample actions (B, n) for observations ``obs``; remember them for ``process_step``."""
        first = next(iter(obs.values()))
        shape = (first.shape[0], self.model.num_actions)
        noise = torch.randn(shape, generator=self.generator, device=first.device)
        if self._graphed_sample is None:
            drawn = self._sample({"obs": obs, "noise": noise})
        else:  # the recorded outputs are overwritten by the next step: the env gets its own action
            drawn = dict(self._graphed_sample({"obs": obs, "noise": noise}))
            drawn["action"] = drawn["action"].clone()
        self._step = {"obs": obs, **drawn}
        return drawn["action"]

    def _sample(self, inputs: dict[str, Any]) -> dict[str, torch.Tensor]:
        """The policy's action for observations ``inputs["obs"]`` and standard-normal ``inputs["noise"]``
        (B, n): {"action" (B, n), "log_prob" (B,), "value" (B,) in return units}."""
        mean, log_std, value, _ = self.model(inputs["obs"])
        std = log_std.exp().expand_as(mean)
        action = mean + std * inputs["noise"]
        log_prob = torch.distributions.Normal(mean, std, validate_args=False).log_prob(action).sum(-1)
        return {"action": action, "log_prob": log_prob, "value": self.values(value)}

    @torch.no_grad()
    def process_step(
        self, reward: torch.Tensor, terminated: torch.Tensor, truncated: torch.Tensor, info: dict[str, Any]
    ) -> None:
        """Store the transition of the last ``act``; with ``bootstrap_timeouts``, add γ·V(final obs)
        to the reward of time-outs (the final observation is ``info["final_obs"]``)."""
        reward = reward.clone()
        if self.config.bootstrap_timeouts and "final_obs" in info:
            final_values = self.values(self.model.value(info["final_obs"]))
            reward += self.config.gamma * final_values * truncated.to(reward.dtype)
        s = self._step
        self.storage.add(s["obs"], s["action"], s["log_prob"], s["value"], reward, terminated | truncated)

    @torch.no_grad()
    def compute_returns(self, next_obs: Obs) -> None:
        """GAE in return units, then store advantages (normalised) and value targets in head units.

        ``next_obs``: the observation after the rollout's last step (bootstraps the last values).
        """
        c, buffer = self.config, self.storage
        last_values = self.values(self.model.value(next_obs))
        advantages, returns = compute_gae(buffer.rewards, buffer.values, buffer.dones, last_values, c.gamma, c.lam)
        if self.value_scaler is not None:
            self.value_scaler.update(returns.reshape(-1, 1))
        buffer.returns = self._normalise(returns)
        buffer.values = self._normalise(buffer.values)
        buffer.advantages = (advantages - advantages.mean()) / (advantages.std() + 1e-8)

    # ------------------------------------------------------------------------- the update

    def update(self) -> dict[str, float]:
        """``epochs`` passes of minibatch SGD; then the observation statistics; clears the buffer.

        Returns the mean of each loss term (``loss/<name>``), auxiliary metrics
        (``<loss>/<metric>``) and PPO diagnostics (``ppo/<name>``).
        """
        with tf32_matmuls(self.config.tf32_update):
            return self._update()

    def _update(self) -> dict[str, float]:
        c, buffer = self.config, self.storage
        if c.bf16_update:
            self._rescore_log_probs()
        aux_batches = {aux.name: aux.prepare(buffer, c.minibatches, self.generator) for aux in self.aux_losses}
        sums: dict[str, torch.Tensor] = {}
        counts: dict[str, int] = {}
        for epoch in range(c.epochs):
            active = [aux for aux in self.aux_losses if epoch < aux_epochs(c.epochs, aux.config.epoch_ratio)]
            epoch_kl = []
            for i, batch in enumerate(buffer.minibatches(c.minibatches, self.generator)):
                if self._graphed is not None:
                    metrics = self._graphed(batch)  # its tensors are overwritten by the next minibatch
                else:
                    metrics = self._minibatch_step(batch, [(aux, aux_batches[aux.name][i]) for aux in active])
                if c.kl_adaptive:  # a copy: a graphed step overwrites its outputs at the next minibatch
                    epoch_kl.append(metrics["ppo/approx_kl"].clone())
                for name, value in metrics.items():
                    sums[name] = sums.get(name, 0.0) + value
                    counts[name] = counts.get(name, 0) + 1
            if c.kl_adaptive:
                self._adapt_lr(float(torch.stack(epoch_kl).mean()))
        out = {name: float(total / counts[name]) for name, total in sums.items()}
        out["ppo/explained_variance"] = float(explained_variance(buffer.values, buffer.returns))
        out["ppo/action_std"] = float(self.model.clamped_log_std().detach().exp().mean())
        out["ppo/lr"] = self.lr
        self.model.update_normalizers(buffer.flat_obs())
        buffer.clear()
        return out

    def _minibatch_step(self, batch: dict, aux: list[tuple[AuxLoss, Any]]) -> dict[str, torch.Tensor]:
        """One backward of the weighted loss terms, PPO's Adam step, then each active loss's own step."""
        c = self.config
        terms, diagnostics, latent = self._ppo_loss(batch)
        weights = {"surrogate": 1.0, "value": c.value_coef, "entropy": -c.entropy_coef}
        metrics = {f"ppo/{name}": value_ for name, value_ in diagnostics.items()}
        for loss_fn, aux_batch in aux:
            terms[loss_fn.name], aux_metrics = loss_fn.loss(self.model, batch, latent, aux_batch)
            weights[loss_fn.name] = loss_fn.config.weight
            metrics.update({f"{loss_fn.name}/{k}": v for k, v in aux_metrics.items()})
        total = weighted_sum(terms, weights)
        self.optimizer.zero_grad(set_to_none=True)
        for loss_fn, _ in aux:
            loss_fn.optimizer.zero_grad(set_to_none=True)
        total.backward()
        # the clip covers the actor-critic (encoder included), never the auxiliary heads
        metrics["ppo/grad_norm"] = nn.utils.clip_grad_norm_(self.model.parameters(), c.max_grad_norm)
        self.optimizer.step()
        self.model.after_optimizer_step()
        for loss_fn, _ in aux:
            loss_fn.optimizer.step()
            loss_fn.after_step(self.model)
        metrics.update({f"loss/{name}": value_.detach() for name, value_ in terms.items()})
        metrics["loss/total"] = total.detach()
        return metrics

    def _ppo_terms(self, batch: dict) -> tuple[dict[str, torch.Tensor], dict[str, torch.Tensor], torch.Tensor]:
        """The forward pass on a minibatch and PPO's loss terms: (terms, diagnostics, actor latent)."""
        c = self.config
        mean, log_std, value, latent = self._forward(batch["obs"])
        dist = torch.distributions.Normal(mean, log_std.exp().expand_as(mean), validate_args=False)
        terms, diagnostics = ppo_terms(
            dist.log_prob(batch["actions"]).sum(-1),
            batch["log_probs"],
            batch["advantages"],
            value,
            batch["values"],
            batch["returns"],
            dist.entropy().sum(-1),
            ratio_clip=c.ratio_clip,
            value_clip=c.value_clip,
        )
        return terms, diagnostics, latent

    @torch.no_grad()
    def _rescore_log_probs(self) -> None:
        """The rollout's log-probabilities under the update's own bfloat16 forward pass.

        The rollout scored its actions in FP32; the same weights in bfloat16 give means rounded to 8
        significant bits, and the log-ratio error (about the rounding over the std, summed over the
        action dimensions) would exceed the clip once the policy's std is small. Scoring the old
        policy with the forward the update uses makes every ratio start at 1.
        """
        buffer = self.storage
        mean, log_std, _, _ = self._forward(buffer.flat_obs())
        dist = torch.distributions.Normal(mean, log_std.exp().expand_as(mean), validate_args=False)
        buffer.log_probs.copy_(dist.log_prob(buffer.actions.flatten(0, 1)).sum(-1).view_as(buffer.log_probs))

    def _forward(self, obs: Obs) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
        """The model's outputs for the update, in FP32; under bfloat16 autocast with ``bf16_update``."""
        if not self.config.bf16_update:
            return self.model(obs)
        device_type = self.storage.values.device.type
        with torch.autocast(device_type=device_type, dtype=torch.bfloat16):
            mean, log_std, value, latent = self.model(obs)
        return mean.float(), log_std.float(), value.float(), latent.float()

    def _adapt_lr(self, kl: float) -> None:
        c = self.config
        self.lr = kl_adaptive_lr(self.lr, kl, c.kl_target, c.kl_factor, c.lr_min, c.lr_max)
        for group in self.optimizer.param_groups:
            if torch.is_tensor(group["lr"]):
                group["lr"].fill_(self.lr)  # the tensor a CUDA graph reads
            else:
                group["lr"] = self.lr

    # ------------------------------------------------------------------------ checkpoints

    def state_dict(self) -> dict[str, Any]:
        """Optimiser, learning rate, value scaler, generator and each auxiliary loss's state."""
        return {
            "optimizer": self.optimizer.state_dict(),
            "lr": self.lr,
            "value_scaler": None if self.value_scaler is None else self.value_scaler.state_dict(),
            "generator": self.generator.get_state(),
            "aux": {aux.name: aux.state_dict() for aux in self.aux_losses},
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore ``state_dict``'s output."""
        self.optimizer.load_state_dict(state["optimizer"])
        self.lr = float(state["lr"])
        if self.value_scaler is not None:
            self.value_scaler.load_state_dict(state["value_scaler"])
        self.generator.set_state(state["generator"].cpu())  # RNG states are CPU byte tensors
        for aux in self.aux_losses:
            aux.load_state_dict(state["aux"][aux.name])

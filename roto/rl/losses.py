"""PPO's loss terms (pure): clipped surrogate, clipped value loss, entropy bonus."""

from __future__ import annotations

import torch


def ppo_loss(
    log_prob: torch.Tensor,
    old_log_prob: torch.Tensor,
    advantages: torch.Tensor,
    values: torch.Tensor,
    old_values: torch.Tensor,
    returns: torch.Tensor,
    entropy: torch.Tensor,
    ratio_clip: float,
    value_clip: float,
    value_coef: float,
    entropy_coef: float,
) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    """The PPO loss of one minibatch.

    Args:
        log_prob, old_log_prob: (N,) log pi(a|s) under the current and the rollout policy.
        advantages: (N,) (already normalised).
        values, old_values, returns: (N,) current value prediction, rollout prediction, target.
        entropy: (N,) policy entropy per sample.
        ratio_clip: epsilon of the clipped surrogate.
        value_clip: the value prediction is clipped to old_values ± value_clip; the loss is the
            squared error of the clipped prediction (roto's form).
        value_coef, entropy_coef: weights.

    Returns:
        (loss scalar, metrics: policy_loss, value_loss, entropy, approx_kl, clip_fraction), metrics detached.
    """
    log_ratio = log_prob - old_log_prob
    ratio = log_ratio.exp()
    surrogate = advantages * ratio
    clipped = advantages * ratio.clamp(1.0 - ratio_clip, 1.0 + ratio_clip)
    policy_loss = -torch.min(surrogate, clipped).mean()
    values_clipped = old_values + (values - old_values).clamp(-value_clip, value_clip)
    value_loss = (returns - values_clipped).square().mean()
    entropy_mean = entropy.mean()
    loss = policy_loss + value_coef * value_loss - entropy_coef * entropy_mean
    with torch.no_grad():
        approx_kl = ((ratio - 1.0) - log_ratio).mean()
        clip_fraction = ((ratio - 1.0).abs() > ratio_clip).float().mean()
    metrics = {
        "policy_loss": policy_loss.detach(),
        "value_loss": value_loss.detach(),
        "entropy": entropy_mean.detach(),
        "approx_kl": approx_kl,
        "clip_fraction": clip_fraction,
    }
    return loss, metrics


def kl_adaptive_lr(lr: float, kl: float, target: float, factor: float, lr_min: float, lr_max: float) -> float:
    """KL-adaptive learning rate: divide by ``factor`` if kl > 2·target, multiply if kl < target/2."""
    if kl > 2.0 * target:
        lr = lr / factor
    elif 0.0 < kl < 0.5 * target:
        lr = lr * factor
    return min(max(lr, lr_min), lr_max)

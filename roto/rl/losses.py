"""PPO's loss terms (pure): clipped surrogate, clipped value loss, entropy; their weighted sum."""

from __future__ import annotations

import torch


def ppo_terms(
    log_prob: torch.Tensor,
    old_log_prob: torch.Tensor,
    advantages: torch.Tensor,
    values: torch.Tensor,
    old_values: torch.Tensor,
    returns: torch.Tensor,
    entropy: torch.Tensor,
    *,
    ratio_clip: float,
    value_clip: float,
) -> tuple[dict[str, torch.Tensor], dict[str, torch.Tensor]]:
    """PPO's loss terms on one minibatch, unweighted.

    Args:
        log_prob, old_log_prob: (N,) log pi(a|s) under the current and the rollout policy.
        advantages: (N,) (already normalised).
        values, old_values, returns: (N,) current value prediction, rollout prediction, target.
        entropy: (N,) policy entropy per sample.
        ratio_clip: epsilon of the clipped surrogate.
        value_clip: the value prediction is clipped to old_values ± value_clip; the value term is the
            squared error of the clipped prediction (roto's form).

    Returns:
        (terms {"surrogate", "value", "entropy"}: scalars with gradients, where the surrogate is
        the negated clipped objective and "entropy" the mean entropy (a bonus: weight it negatively);
        diagnostics {"approx_kl", "clip_fraction"}: detached scalars).
    """
    log_ratio = log_prob - old_log_prob
    ratio = log_ratio.exp()
    surrogate = advantages * ratio
    clipped = advantages * ratio.clamp(1.0 - ratio_clip, 1.0 + ratio_clip)
    values_clipped = old_values + (values - old_values).clamp(-value_clip, value_clip)
    terms = {
        "surrogate": -torch.min(surrogate, clipped).mean(),
        "value": (returns - values_clipped).square().mean(),
        "entropy": entropy.mean(),
    }
    with torch.no_grad():
        diagnostics = {
            "approx_kl": ((ratio - 1.0) - log_ratio).mean(),
            "clip_fraction": ((ratio - 1.0).abs() > ratio_clip).float().mean(),
        }
    return terms, diagnostics


def weighted_sum(terms: dict[str, torch.Tensor], weights: dict[str, float]) -> torch.Tensor:
    """Σ weights[name] · terms[name] over ``terms`` (every term needs a weight)."""
    missing = sorted(set(terms) - set(weights))
    if missing:
        raise KeyError(f"loss terms without a weight: {missing}")
    return sum((weights[name] * value for name, value in terms.items()), torch.zeros((), device=_device(terms)))


def _device(terms: dict[str, torch.Tensor]) -> torch.device:
    return next(iter(terms.values())).device


def kl_adaptive_lr(lr: float, kl: float, target: float, factor: float, lr_min: float, lr_max: float) -> float:
    """KL-adaptive learning rate: divide by ``factor`` if kl > 2·target, multiply if kl < target/2."""
    if kl > 2.0 * target:
        lr = lr / factor
    elif 0.0 < kl < 0.5 * target:
        lr = lr * factor
    return min(max(lr, lr_min), lr_max)

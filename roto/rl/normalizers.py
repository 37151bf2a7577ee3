"""Running mean / standard deviation, merged batch by batch (Chan et al.'s parallel update)."""

from __future__ import annotations

import torch
from torch import nn


class RunningStandardScaler(nn.Module):
    """Standardise inputs with running statistics: (x - mean) / sqrt(var + eps), clipped to ±clip.

    The statistics are buffers, so they live in the module's ``state_dict`` (and therefore in the
    saved policy). ``update`` folds a batch in; ``forward`` never updates.

    Args:
        size: feature dimension D.
        clip: symmetric clip of the standardised value (None: no clip).
        eps: added to the variance.
    """

    def __init__(self, size: int, clip: float | None = 5.0, eps: float = 1e-8) -> None:
        super().__init__()
        self.clip, self.eps = clip, eps
        self.register_buffer("mean", torch.zeros(size, dtype=torch.float64))
        self.register_buffer("var", torch.ones(size, dtype=torch.float64))
        self.register_buffer("count", torch.zeros((), dtype=torch.float64))

    @torch.no_grad()
    def update(self, x: torch.Tensor) -> None:
        """Fold a batch (N, D) into the running statistics."""
        x = x.reshape(-1, self.mean.numel()).to(torch.float64)
        n = x.shape[0]
        if n == 0:
            return
        batch_mean = x.mean(dim=0)
        batch_var = x.var(dim=0, unbiased=False)
        total = self.count + n
        delta = batch_mean - self.mean
        self.mean += delta * n / total
        m2 = self.var * self.count + batch_var * n + delta.square() * self.count * n / total
        self.var.copy_(m2 / total)
        self.count.copy_(total)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """Standardised x (..., D), same dtype as x."""
        std = torch.sqrt(self.var + self.eps).to(x.dtype)
        y = (x - self.mean.to(x.dtype)) / std
        return y if self.clip is None else y.clamp(-self.clip, self.clip)

    def inverse(self, y: torch.Tensor) -> torch.Tensor:
        """Undo the standardisation (no clip): y · std + mean."""
        return y * torch.sqrt(self.var + self.eps).to(y.dtype) + self.mean.to(y.dtype)

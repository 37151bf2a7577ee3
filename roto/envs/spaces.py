"""The action space: a Gymnasium ``Box`` bounded on every side, with a one-call ``sample``.

Gymnasium's ``Box.sample`` sorts the coordinates into four kinds of interval on every call (some
twenty numpy operations, about 20 µs) before drawing the bounded ones with one ``uniform`` call;
for a one-world env stepped with random actions (Gymnasium's ``benchmark_step``, random-policy
baselines) that is a tenth of a control step. Every coordinate of roto's action space is bounded,
so ``BoundedBox.sample`` makes only that ``uniform`` call (with scalar bounds where every
coordinate shares them, numpy's fastest form): the same numbers from the same generator state as
``Box.sample`` (tests/envs/test_spaces.py).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np


class BoundedBox(gym.spaces.Box):
    """A float ``Box`` with finite bounds on every coordinate (read once, at construction, as
    ``Box`` reads which coordinates are bounded)."""

    def __init__(self, low: Any, high: Any, shape: tuple[int, ...] | None = None, dtype: Any = np.float32, **kwargs):
        super().__init__(low, high, shape, dtype, **kwargs)
        if self.dtype.kind != "f" or not self.is_bounded("both"):
            raise ValueError(f"BoundedBox needs a float dtype and finite bounds, got dtype={self.dtype}, {self}")
        # uniform's bounds as Box.sample passes them (float64 after numpy's conversion); one
        # Python float where every coordinate has the same bound
        low64, high64 = self.low.astype(np.float64), self.high.astype(np.float64)
        self._uniform_low = float(low64.flat[0]) if (low64 == low64.flat[0]).all() else low64
        self._uniform_high = float(high64.flat[0]) if (high64 == high64.flat[0]).all() else high64

    def sample(self, mask: None = None, probability: None = None) -> np.ndarray:
        """A uniform sample inside the box (masks are unsupported, as for ``Box``)."""
        if mask is not None or probability is not None:
            return super().sample(mask, probability)  # raises Gymnasium's own error
        return self.np_random.uniform(self._uniform_low, self._uniform_high, self.shape).astype(self.dtype)

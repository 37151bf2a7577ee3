"""Episode starts drawn ahead, many at a time, and handed out in order as worlds reset.

An episode start is everything a reset world needs: its initial qpos, joint targets and first
observation frame. The first frame needs the contact sensors at the start state, which takes a
physics evaluation; drawing starts one reset at a time (a handful of worlds per control step under
random actions) paid that evaluation, and some sixty small torch ops, on every step. The pool draws
``size`` starts in one batch (one batched sensor evaluation, spread over all threads or GPU worlds)
and each reset then only copies rows.

The starts are drawn from the env's generator in pool order, so a seed still fixes every episode
start; the draws are the same distribution as drawing per reset, only their order in the random
stream differs.
"""

from __future__ import annotations

from collections.abc import Callable

import torch

Starts = dict[str, torch.Tensor]
"""Name -> tensor with one row per episode start (leading dimension n)."""


class StartPool:
    """A FIFO of episode starts, refilled ``size`` at a time by ``draw(size)``."""

    def __init__(self, draw: Callable[[int], Starts], size: int) -> None:
        if size < 1:
            raise ValueError(f"start pool size must be >= 1, got {size}")
        self.size = size
        self._draw = draw
        self._rows: Starts = {}
        self._next = 0

    @property
    def remaining(self) -> int:
        """Starts drawn and not yet handed out."""
        if not self._rows:
            return 0
        return len(next(iter(self._rows.values()))) - self._next

    def take(self, n: int) -> Starts:
        """The next ``n`` starts, (n, ...) per name; draws ``size`` more first where fewer are left."""
        while self.remaining < n:
            fresh = self._draw(self.size)
            if self.remaining:
                fresh = {name: torch.cat([rows[self._next :], fresh[name]]) for name, rows in self._rows.items()}
            self._rows, self._next = fresh, 0
        start, self._next = self._next, self._next + n
        return {name: rows[start : self._next] for name, rows in self._rows.items()}

    def clear(self) -> None:
        """Drop every start drawn so far."""
        self._rows, self._next = {}, 0

    def state_dict(self) -> dict[str, Starts]:
        """Copies of the starts not yet handed out."""
        return {"rows": {name: rows[self._next :].clone() for name, rows in self._rows.items()}}

    def load_state_dict(self, state: dict[str, Starts], device: torch.device) -> None:
        """Restore what ``state_dict`` returned."""
        self._rows = {name: rows.clone().to(device) for name, rows in state["rows"].items()}
        self._next = 0

"""Fixed column selections of batched arrays, as views where the columns are evenly spaced.

Reading ``x[..., index]`` with an index tensor copies through a general gather (about 15 µs per
call on 256 worlds, a dozen calls per env step). Most of the env's selections are evenly spaced
(a hand's joints, every 4th sensor value, each ball's 3 coordinates among its 7 qpos), and those
can be read as a strided view instead. ``Columns.take`` returns the view where it can and falls
back to the gather otherwise, with identical values either way (tests/envs/test_columns.py).

Views alias the array they come from: read them before that array changes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch


@dataclass(frozen=True)
class Columns:
    """Columns ``index`` (shape ``(k,)`` or ``(n, k)``) of the last axis of an array.

    ``start``/``row_step``/``col_step`` describe the index when it is the grid
    ``start + row_step·i + col_step·j`` with positive steps and ``col_step·(k-1) < row_step``
    (rows do not overlap); ``start`` is None otherwise.
    """

    index: torch.Tensor
    start: int | None
    row_step: int
    col_step: int

    @classmethod
    def of(cls, index: np.ndarray | list, device: torch.device | str = "cpu") -> Columns:
        """Selector for the integer ``index`` (1-D or 2-D)."""
        array = np.asarray(index, dtype=np.int64)
        if array.ndim not in (1, 2):
            raise ValueError(f"column index must be 1-D or 2-D, got shape {array.shape}")
        tensor = torch.as_tensor(array, device=device)
        grid = _grid(array if array.ndim == 2 else array[None])
        start, row_step, col_step = grid if grid is not None else (None, 0, 0)
        return cls(index=tensor, start=start, row_step=row_step, col_step=col_step)

    def take(self, x: torch.Tensor) -> torch.Tensor:
        """``x[..., index]``, shape ``(*x.shape[:-1], *index.shape)``: a view of ``x`` where possible."""
        view = self._view(x)
        if view is not None:
            return view
        return x.index_select(-1, self.index) if self.index.dim() == 1 else x[..., self.index]

    def put(self, x: torch.Tensor, values: torch.Tensor) -> None:
        """``x[..., index] = values`` in place (``values`` broadcast to ``take``'s shape)."""
        view = self._view(x)
        if view is None:
            x[..., self.index] = values
        else:
            view.copy_(values)

    def _view(self, x: torch.Tensor) -> torch.Tensor | None:
        """The selection as a strided view of ``x``, or None where it is not a grid that fits in ``x``."""
        if self.start is None:
            return None
        k = self.index.shape[-1]
        stop = self.start + self.col_step * (k - 1) + 1
        if self.index.dim() == 1:  # a plain slice: the cheapest view to make
            return x[..., self.start : stop : self.col_step] if stop <= x.shape[-1] else None
        n = self.index.shape[0]
        if stop + self.row_step * (n - 1) > x.shape[-1]:
            return None
        unit = x.stride(-1)
        return x.as_strided(
            (*x.shape[:-1], n, k),
            (*x.stride()[:-1], self.row_step * unit, self.col_step * unit),
            x.storage_offset() + self.start * unit,
        )


def _grid(index: np.ndarray) -> tuple[int, int, int] | None:
    """(start, row_step, col_step) if ``index`` (n, k) is an evenly spaced grid, else None."""
    n, k = index.shape
    if index.size == 0:
        return None
    start = int(index[0, 0])
    col_step = int(index[0, 1] - index[0, 0]) if k > 1 else 1
    row_step = int(index[1, 0] - index[0, 0]) if n > 1 else col_step * k  # one row: any step past it
    if col_step < 1 or row_step < col_step * (k - 1) + 1 or start < 0:
        return None
    expected = start + row_step * np.arange(n)[:, None] + col_step * np.arange(k)[None]
    if not np.array_equal(index, expected):
        return None
    return start, row_step, col_step

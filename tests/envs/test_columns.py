"""Columns.take / put against plain advanced indexing (the slow reference)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from roto.envs.columns import Columns

INDICES = {
    "contiguous": [0, 1, 2, 3, 4],
    "every 4th": [1, 5, 9, 13],
    "single": [7],
    "two balls' centres": [[3, 4, 5], [10, 11, 12]],
    "one ball's centre": [[9, 10, 11]],
    "strided grid": [[0, 2], [5, 7], [10, 12]],
    "irregular": [0, 1, 3, 4, 6],
    "irregular rows": [[0, 1, 2], [4, 5, 6], [9, 10, 11]],
    "descending": [4, 3, 2],
    "empty": [],
    "grid reaching the last column": [[10, 11, 12], [13, 14, 15]],
    "strided rows reaching the last column": [[3, 5], [8, 10], [13, 15]],
}


@pytest.mark.parametrize("name", list(INDICES))
def test_take_and_put_match_advanced_indexing(name: str) -> None:
    index = np.asarray(INDICES[name], dtype=np.int64)
    columns = Columns.of(index)
    x = torch.arange(3 * 2 * 24, dtype=torch.float64).reshape(3, 2, 24)[..., :16]  # strided, like a view
    reference = x[..., torch.as_tensor(index)]
    taken = columns.take(x)
    assert taken.shape == reference.shape
    assert torch.equal(taken, reference)

    values = -torch.rand(reference.shape, dtype=torch.float64)
    expected = x.clone()
    expected[..., torch.as_tensor(index)] = values
    columns.put(x, values)
    assert torch.equal(x, expected)


@pytest.mark.parametrize("name", ["contiguous", "every 4th", "single", "two balls' centres", "one ball's centre"])
def test_grids_are_read_as_views(name: str) -> None:
    columns = Columns.of(INDICES[name])
    assert columns.start is not None
    x = torch.zeros(4, 16)
    taken = columns.take(x)
    x.fill_(3.0)  # a view sees the change; a gathered copy would not
    assert bool((taken == 3.0).all())


@pytest.mark.parametrize("name", ["irregular", "irregular rows", "descending", "empty"])
def test_other_indices_are_gathered(name: str) -> None:
    assert Columns.of(INDICES[name]).start is None


def test_a_grid_past_the_end_falls_back_to_a_gather() -> None:
    columns = Columns.of([[10, 11, 12], [13, 14, 15]])
    x = torch.arange(15.0)[None]  # column 15 does not exist
    with pytest.raises(IndexError):
        columns.take(x)  # the gather reports it, as plain indexing does


def test_three_dimensional_index_is_refused() -> None:
    with pytest.raises(ValueError, match="1-D or 2-D"):
        Columns.of(np.zeros((2, 2, 2), dtype=np.int64))

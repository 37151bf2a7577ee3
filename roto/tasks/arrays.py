"""The array functions task rules use, for torch tensors and numpy arrays alike.

A task's rule is written once. Every batched env runs it on torch tensors (on any device); the
one-world Gymnasium step runs it on numpy arrays, where a torch op's dispatch would cost more than
its arithmetic (roto.envs.single_world). Operators (``+ - * / < & | ~ ^``), indexing and the
``sum``/``any``/``all`` methods with ``axis=`` mean the same on both; what differs is here. On the
CPU each function gives numpy arrays the same bits as torch tensors (tests/tasks/test_arrays.py),
so both paths make the same trajectories: where the libraries' kernels differ (square roots,
``tanh``), a numpy array goes through torch's.
"""

from __future__ import annotations

from typing import TypeVar

import numpy as np
import torch

Array = TypeVar("Array", torch.Tensor, np.ndarray)


def where(condition: Array, x: Array | float, y: Array | float) -> Array:
    """``x`` where ``condition`` holds, else ``y`` (broadcast; Python scalars keep the array's dtype)."""
    if isinstance(condition, np.ndarray):
        return np.where(condition, x, y)
    return torch.where(condition, x, y)


def flip_rows(x: Array) -> Array:
    """``x`` with its first axis reversed (a view on numpy; no index list, which torch would copy
    to the device)."""
    if isinstance(x, np.ndarray):
        return x[::-1]
    return x.flip(0)


def squared_norm(v: Array) -> Array:
    """Squared Euclidean length over the last axis, (..., 2 or 3) -> (...,), summed in a fixed
    order from elementwise operations (the same bits on numpy and torch, with no torch call)."""
    squares = v * v
    total = squares[..., 0] + squares[..., 1]
    return total + squares[..., 2] if v.shape[-1] == 3 else total


def vector_norm(v: Array) -> Array:
    """Euclidean length over the last axis: (..., n) -> (...,). A numpy array goes through torch's
    CPU kernel (sharing its memory): numpy's norm, and even its square root, differ from torch's
    in the last bit."""
    if isinstance(v, np.ndarray):
        return torch.linalg.vector_norm(torch.from_numpy(v), dim=-1).numpy()
    return torch.linalg.vector_norm(v, dim=-1)


def tanh(x: Array) -> Array:
    """Hyperbolic tangent. A numpy array goes through torch's CPU kernel (sharing its memory):
    numpy's ``tanh`` and torch's differ in the last bit."""
    if isinstance(x, np.ndarray):
        return torch.tanh(torch.from_numpy(x)).numpy()
    return torch.tanh(x)


def as_dtype_of(x: Array, like: Array) -> Array:
    """``x`` converted to ``like``'s dtype (a bool mask to the reward's float dtype)."""
    if isinstance(x, np.ndarray):
        return x.astype(like.dtype)
    return x.to(like.dtype)


def atan2(y: Array, x: Array) -> Array:
    """Elementwise angle of (x, y) in [-pi, pi]. A numpy array goes through torch's CPU kernel
    (sharing its memory), for the same bits on both."""
    if isinstance(y, np.ndarray):
        return torch.atan2(torch.from_numpy(y), torch.from_numpy(x)).numpy()
    return torch.atan2(y, x)


def minimum(x: Array, y: Array | float) -> Array:
    """Elementwise smaller of ``x`` and ``y`` (an array of ``x``'s kind or a number)."""
    if isinstance(x, np.ndarray):
        return np.minimum(x, y)
    return torch.minimum(x, torch.as_tensor(y, dtype=x.dtype, device=x.device))


def zero_on_host(x: Array) -> bool:
    """Whether ``x`` is zero everywhere, where reading it costs nothing: a numpy array or a CPU
    tensor. A tensor on another device is never read (that would wait for the device): False, so
    the caller takes the path that is right for any value."""
    if isinstance(x, np.ndarray):
        return not x.any()
    return x.device.type == "cpu" and not bool(x.any())

"""A pure tensor function recorded once into a CUDA graph and replayed for every call.

The rollout's policy pass (normalise the observations, encoder, policy and value heads, the
action drawn from given noise, its log-probability) launches some tens of small kernels per env
step; on a GPU the host's time to issue them, not the device's time to run them, can cost more
than the simulation (docs/backends.md). ``GraphedCall`` issues them with one launch.

It wraps a function of a nested dict of tensors of fixed shapes that returns a dict of tensors,
draws no random numbers (pass noise in), reads nothing back to the host and changes no state. On
its first call it copies the inputs into tensors of its own, runs the function a few times on a
side stream (CUDA loads its kernels), and records one call; every call then copies the inputs
into the recorded ones and replays. The outputs are the recorded tensors, overwritten by the next
call: use (or copy) them before calling again. Parameters and buffers the function reads (weights,
running statistics) are read where they are, so in-place updates to them reach every replay.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import torch

WARMUP_STEPS = 3
"""Eager steps on a side stream before the capture (PyTorch's guidance for whole-network capture)."""

Metrics = dict[str, torch.Tensor]
"""What a graphed function returns: named tensors."""


def copy_tree(target: Any, source: Any) -> None:
    """Copy a nested dict of tensors into one of the same structure and shapes, in place."""
    if isinstance(target, dict):
        if target.keys() != source.keys():
            raise ValueError(f"a graphed call's inputs changed keys: {sorted(target)} -> {sorted(source)}")
        for key, value in target.items():
            copy_tree(value, source[key])
        return
    if target.shape != source.shape:
        raise ValueError(f"a graphed call's inputs changed shape: {tuple(target.shape)} -> {tuple(source.shape)}")
    target.copy_(source)


def clone_tree(source: Any) -> Any:
    """A copy of a nested dict of tensors, with storage of its own."""
    if isinstance(source, dict):
        return {key: clone_tree(value) for key, value in source.items()}
    return source.detach().clone()


class GraphedCall:
    """``fn(inputs) -> outputs``, replayed from a CUDA graph. This class captures without autograd;
    ``roto.rl.graphed_step.GraphedMinibatchStep`` captures a training step (backward included)."""

    def __init__(self, fn: Callable[[dict], Metrics]) -> None:
        self._fn = fn
        self._graph: torch.cuda.CUDAGraph | None = None
        self._inputs: dict = {}
        self._outputs: Metrics = {}

    def __call__(self, inputs: dict) -> Metrics:
        """``fn``'s outputs for ``inputs`` (valid until the next call)."""
        if self._graph is None:
            self._capture(inputs)
        copy_tree(self._inputs, inputs)
        self._graph.replay()
        return self._outputs

    @torch.no_grad()
    def _capture(self, inputs: dict) -> None:
        """Warm up on a side stream, then record one call."""
        self._inputs = clone_tree(inputs)
        self._warm_up()
        self._record()

    def _warm_up(self) -> None:
        """``WARMUP_STEPS`` calls on the recorded inputs, on a side stream (CUDA loads its kernels)."""
        side = torch.cuda.Stream()
        side.wait_stream(torch.cuda.current_stream())
        with torch.cuda.stream(side):
            for _ in range(WARMUP_STEPS):
                self._fn(self._inputs)
        torch.cuda.current_stream().wait_stream(side)

    def _record(self) -> None:
        """One call on the recorded inputs, captured: its outputs become the recorded outputs."""
        graph = torch.cuda.CUDAGraph()
        with torch.cuda.graph(graph):
            self._outputs = self._fn(self._inputs)
        self._graph = graph

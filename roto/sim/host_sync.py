"""Deliberate waits for the device.

On a CUDA device roto's step reads nothing back except in periodic checks (capacity overflow,
the pool of episode starts, action finiteness). Those reads run inside ``deliberate_host_sync``,
which lifts ``torch.cuda.set_sync_debug_mode`` for their duration, so a test or a user can run the
step under ``set_sync_debug_mode("error")`` and be told of any other wait. ``resolve_device`` names
a device the way tensors report it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import torch


@contextlib.contextmanager
def deliberate_host_sync(device: torch.device) -> Iterator[None]:
    """Within this block, host reads of ``device`` are intended (not reported as sync warnings/errors)."""
    if device.type != "cuda":
        yield
        return
    mode = torch.cuda.get_sync_debug_mode()
    torch.cuda.set_sync_debug_mode(0)
    try:
        yield
    finally:
        torch.cuda.set_sync_debug_mode(mode)


def resolve_device(device: str | torch.device) -> torch.device:
    """``device`` with its index made explicit (``cuda`` -> ``cuda:<current>``), as tensors report it."""
    device = torch.device(device)
    if device.type == "cuda" and device.index is None:
        return torch.device("cuda", torch.cuda.current_device())
    return device

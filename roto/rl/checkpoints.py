"""Writing and safely reading checkpoints.

A checkpoint is a ``torch.save`` of nested dicts and lists of tensors, numbers, strings, booleans
and None. It is read with ``torch.load(..., weights_only=True)``, whose unpickler builds only such
plain data, so a crafted file cannot run code when it is loaded.
"""

from __future__ import annotations

import pathlib
from typing import Any

import torch


def save_checkpoint(state: dict[str, Any], path: pathlib.Path) -> None:
    """Write ``state`` atomically (a temporary file, then a rename)."""
    tmp = path.with_suffix(".tmp")
    torch.save(state, tmp)
    tmp.replace(path)


def load_checkpoint(path: str | pathlib.Path, device: torch.device | str = "cpu") -> dict[str, Any]:
    """The state saved at ``path``, tensors on ``device``.

    Raises FileNotFoundError when there is no file, and ValueError when the file is not a roto
    checkpoint (not a torch file, or one holding anything but plain data).
    """
    path = pathlib.Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"checkpoint {str(path)!r} does not exist")
    try:
        state = torch.load(path, weights_only=True, map_location=device)
    except Exception as error:  # a foreign file fails in the unpickler in many ways (KeyError, EOFError ...)
        first_line = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise ValueError(
            f"{str(path)!r} is not a roto checkpoint (roto train writes them under <run_dir>/checkpoints/); "
            f"loading it failed: {first_line}"
        ) from None
    if not isinstance(state, dict) or not {"model", "train", "agent"} <= state.keys():
        raise ValueError(f"{str(path)!r} is not a roto checkpoint: it lacks the model, train and agent entries")
    return state

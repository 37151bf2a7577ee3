"""Writing and safely reading checkpoints.

A checkpoint is a ``torch.save`` of nested dicts and lists of tensors, numbers, strings, booleans
and None. It is read with ``torch.load(..., weights_only=True)``, whose unpickler builds only such
plain data, so a crafted file cannot run code when it is loaded.
"""

from __future__ import annotations

import pathlib
from typing import Any

import torch

from roto.artifact_formats import FORMAT_KEY, check_format


def save_checkpoint(state: dict[str, Any], path: pathlib.Path) -> None:
    """Write ``state`` atomically (a temporary file, then a rename)."""
    tmp = path.with_suffix(".tmp")
    torch.save(state, tmp)
    tmp.replace(path)


def load_checkpoint(path: str | pathlib.Path, device: torch.device | str = "cpu") -> dict[str, Any]:
    """The state saved at ``path``, tensors on ``device``.

    Raises FileNotFoundError when there is no file (IsADirectoryError for a directory), and
    ValueError when the file is not a roto checkpoint (not a torch file, truncated or corrupted, or
    one holding anything but plain data), in one line that never advises loading it unsafely.
    """
    path = pathlib.Path(path)
    if not path.is_file():
        if path.is_dir():
            raise IsADirectoryError(f"checkpoint {str(path)!r} is a directory; give a .pt file in it")
        raise FileNotFoundError(f"checkpoint {str(path)!r} does not exist")
    where = f"{str(path)!r} is not a roto checkpoint (roto train writes them under <run_dir>/checkpoints/)"
    with path.open("rb") as file:
        head = file.read(4)
    if not head.startswith(b"PK"):  # torch.save writes a zip archive
        raise ValueError(f"{where}: it is not a torch file (it starts with {head!r})")
    try:
        state = torch.load(path, weights_only=True, map_location=device)
    except Exception as error:  # a foreign file fails in the unpickler in many ways (KeyError, EOFError ...)
        raise ValueError(f"{where}: {_load_failure(error)}") from None
    run_entries = {"spec"} if isinstance(state, dict) and "spec" in state else {"train", "agent"}  # formats 1, 2
    if not isinstance(state, dict) or not {"model", *run_entries} <= state.keys():
        raise ValueError(f"{str(path)!r} is not a roto checkpoint: it lacks the model and spec entries")
    check_format("checkpoint", state.get(FORMAT_KEY), f"checkpoint {str(path)!r}")
    return state


def _load_failure(error: Exception) -> str:
    """Why ``torch.load(weights_only=True)`` refused a file, in roto's words: torch's own message
    advises loading unsafely, which roto never does."""
    text = str(error)
    if "Weights only load failed" in text:
        return "it holds pickled objects beyond tensors, numbers and strings, or is corrupted; roto never loads those"
    if "zip archive" in text or "central directory" in text or isinstance(error, (EOFError, RuntimeError, OSError)):
        return "it is truncated or corrupted (its archive cannot be read)"
    return f"reading it failed ({type(error).__name__})"

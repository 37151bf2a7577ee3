"""Sequence windows for forward dynamics, and the ring buffer the memory variant keeps them in."""

from __future__ import annotations

from collections.abc import Mapping

import torch


def sequence_windows(obs: Mapping[str, torch.Tensor], actions: torch.Tensor, dones: torch.Tensor, length: int) -> dict:
    """Every window of ``length`` consecutive observations with no episode end between them.

    A window starting at step t of env b holds observations t .. t+length-1 and the actions taken
    at those steps (the last one is not needed for a prediction but kept for a uniform shape). It
    is valid when none of the steps t .. t+length-2 ended an episode (the observation after an
    ending step is the next episode's first). Windows overlap: every start is used.

    Args:
        obs: {group: (T, B, D_g)}; actions: (T, B, n); dones: (T, B) bool; length: L >= 2.

    Returns:
        {"obs": {group: (S, L, D_g)}, "actions": (S, L, n)}: the S valid windows, ordered by start
        step, then env.
    """
    steps = dones.shape[0]
    if not 2 <= length <= steps:
        raise ValueError(f"sequence length must be in [2, {steps}] for {steps} steps, got {length}")
    ended = dones[: steps - 1].unfold(0, length - 1, 1)  # (T - L + 1 starts, B, L - 1)
    t, b = torch.nonzero(~ended.any(dim=-1), as_tuple=True)
    rows = t[:, None] + torch.arange(length, device=t.device)  # (S, L)
    return {
        "obs": {group: value[rows, b[:, None]] for group, value in obs.items()},
        "actions": actions[rows, b[:, None]],
    }


def split_windows(windows: dict, parts: int, generator: torch.Generator, limit: int = 0) -> list[dict]:
    """Shuffle the S windows and cut them into ``parts`` batches of floor(S' / parts), where S' is S
    or, when ``limit`` > 0, at most ``limit`` (the rest of the shuffled windows is dropped).

    With fewer windows than parts every batch is empty; a loss on an empty batch is skipped.
    """
    count = windows["actions"].shape[0]
    order = torch.randperm(count, generator=generator, device=generator.device).to(windows["actions"].device)
    size = (min(count, limit) if limit > 0 else count) // parts
    batches = []
    for i in range(parts):
        index = order[i * size : (i + 1) * size]
        batches.append({"obs": {g: v[index] for g, v in windows["obs"].items()}, "actions": windows["actions"][index]})
    return batches


class SequenceMemory:
    """A FIFO of at most ``capacity`` windows, fed with every rollout, and windows that span two rollouts.

    The last L - 1 steps of each rollout are kept, so the next rollout's windows may start in them.

    Args:
        capacity: windows held (the oldest are overwritten).
        length: L, observations per window.
    """

    def __init__(self, capacity: int, length: int) -> None:
        if capacity < 1:
            raise ValueError(f"memory capacity must be >= 1, got {capacity}")
        self.capacity, self.length = capacity, length
        self.windows: dict | None = None  # {"obs": {group: (C, L, D)}, "actions": (C, L, n)} once fed
        self.tail: dict | None = None  # the previous rollout's last L - 1 steps
        self.head = 0  # next slot to write
        self.count = 0  # filled slots

    def add_rollout(self, obs: Mapping[str, torch.Tensor], actions: torch.Tensor, dones: torch.Tensor) -> None:
        """Store every valid window of a rollout ({group: (T, B, D)}, (T, B, n), (T, B)), with the tail."""
        steps = {"obs": dict(obs), "actions": actions, "dones": dones}
        if self.tail is not None:
            steps = _cat_time(self.tail, steps)
        new = sequence_windows(steps["obs"], steps["actions"], steps["dones"], self.length)
        keep = self.length - 1
        self.tail = {
            "obs": {g: v[-keep:].clone() for g, v in steps["obs"].items()},
            "actions": steps["actions"][-keep:].clone(),
            "dones": steps["dones"][-keep:].clone(),
        }
        self._write(new)

    def contents(self) -> dict:
        """The filled windows (a view; order is irrelevant, batches are shuffled)."""
        if self.windows is None:
            raise RuntimeError("the sequence memory is empty; add a rollout first")
        n = self.count
        return {"obs": {g: v[:n] for g, v in self.windows["obs"].items()}, "actions": self.windows["actions"][:n]}

    def _write(self, new: dict) -> None:
        count = new["actions"].shape[0]
        if self.windows is None:
            self.windows = {
                "obs": {g: v.new_zeros(self.capacity, *v.shape[1:]) for g, v in new["obs"].items()},
                "actions": new["actions"].new_zeros(self.capacity, *new["actions"].shape[1:]),
            }
        if count > self.capacity:  # only the newest fit
            new = {
                "obs": {g: v[-self.capacity :] for g, v in new["obs"].items()},
                "actions": new["actions"][-self.capacity :],
            }
            count = self.capacity
        slots = (self.head + torch.arange(count, device=new["actions"].device)) % self.capacity
        for group, value in new["obs"].items():
            self.windows["obs"][group][slots] = value
        self.windows["actions"][slots] = new["actions"]
        self.head = (self.head + count) % self.capacity
        self.count = min(self.capacity, self.count + count)

    def state_dict(self) -> dict:
        """Windows, tail and ring position (everything a resumed run needs)."""
        return {"windows": self.windows, "tail": self.tail, "head": self.head, "count": self.count}

    def load_state_dict(self, state: dict) -> None:
        """Restore ``state_dict``'s output."""
        self.windows, self.tail = state["windows"], state["tail"]
        self.head, self.count = int(state["head"]), int(state["count"])


def _cat_time(first: dict, second: dict) -> dict:
    return {
        "obs": {g: torch.cat([first["obs"][g], v]) for g, v in second["obs"].items()},
        "actions": torch.cat([first["actions"], second["actions"]]),
        "dones": torch.cat([first["dones"], second["dones"]]),
    }

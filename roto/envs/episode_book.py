"""The running statistics of the episodes under way in B worlds, and what an ended episode reports.

A part of ``RotoEnv`` with public fields: the single-world numpy step (``roto.envs.single_world``)
adds to them in place, as ``EpisodeBook.add`` does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import torch


@dataclass
class EpisodeBook:
    """Per-world episode statistics, each (B,) on the env's device.

    Attributes:
        length: int64 control steps of each episode so far.
        ret: float64 return so far.
        term_sums: reward term name -> (B,) its sum so far (a term appears with its first step).
        nonfinite_resets: () int64, worlds reset because their physics went non-finite.
    """

    length: torch.Tensor
    ret: torch.Tensor
    term_sums: dict[str, torch.Tensor] = field(default_factory=dict)
    nonfinite_resets: torch.Tensor | None = None

    @classmethod
    def empty(cls, num_envs: int, device: torch.device) -> EpisodeBook:
        """No step yet in any of ``num_envs`` worlds."""
        return cls(
            length=torch.zeros(num_envs, dtype=torch.int64, device=device),
            ret=torch.zeros(num_envs, dtype=torch.float64, device=device),
            nonfinite_resets=torch.zeros((), dtype=torch.int64, device=device),
        )

    def add(self, reward: torch.Tensor, terms: dict[str, torch.Tensor]) -> None:
        """One control step: ``reward`` (B,) and its named ``terms`` (B,) each."""
        self.length += 1
        self.ret += reward
        for name, value in terms.items():
            if name in self.term_sums:
                self.term_sums[name] += value
            else:
                self.term_sums[name] = value.clone()

    def info(self, truncated: torch.Tensor, metrics: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
        """What the episodes ending now report (rows of the worlds that did not end are meaningless):
        return ``r``, length ``l``, ``time_out`` (``truncated`` (B,)), the task's ``metrics`` and
        each reward term's sum (``reward/<term>``)."""
        info = {"r": self.ret.to(torch.float32, copy=True), "l": self.length.clone(), "time_out": truncated.clone()}
        info.update({name: value.clone() for name, value in metrics.items()})
        info.update({f"reward/{name}": value.to(torch.float32, copy=True) for name, value in self.term_sums.items()})
        return info

    def clear(self, done: torch.Tensor) -> None:
        """Start the episodes of the worlds where ``done`` (B,) over."""
        self.length.masked_fill_(done, 0)
        self.ret.masked_fill_(done, 0.0)
        for value in self.term_sums.values():
            value.masked_fill_(done, 0.0)

    def state_dict(self) -> dict[str, object]:
        """Copies of the running statistics (the keys of the env's ``state_dict``)."""
        return {
            "episode_length": self.length.clone(),
            "episode_return": self.ret.clone(),
            "term_sums": {name: value.clone() for name, value in self.term_sums.items()},
            "nonfinite_resets": int(self.nonfinite_resets),
        }

    def load_state_dict(self, state: dict[str, object], device: torch.device) -> None:
        """Restore what ``state_dict`` returned."""
        self.length = state["episode_length"].clone().to(device)
        self.ret = state["episode_return"].clone().to(device)
        self.term_sums = {name: value.clone().to(device) for name, value in state["term_sums"].items()}
        self.nonfinite_resets.fill_(int(state["nonfinite_resets"]))

"""A toy batched env with RotoEnv's interface, learnable by PPO in seconds.

Each step shows a random target x ~ U(-1, 1)^2; the reward is 1 - |a - x|^2 / 2 for the action a.
Episodes last 8 steps. A random policy earns about 4 per episode, a good one close to 8.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import torch

from roto.envs.config import EnvConfig

EPISODE_STEPS = 8


@dataclass(frozen=True)
class _ToyTask:
    metric_names: tuple[str, ...] = ("hits",)
    headline_metric: str = "hits"
    path_metric_names: tuple[str, ...] = ()
    selection_metric: str | None = None


class ToyEnv:
    """B toy worlds; ``frame_sizes`` and the info layout match RotoEnv's."""

    def __init__(self, config: EnvConfig) -> None:
        self.config = config
        self.num_envs = config.num_envs
        self.device = torch.device("cpu")
        self.num_actions = 2
        self.frame_sizes = {"proprio": 2}
        self.task = _ToyTask()
        self._generator = torch.Generator().manual_seed(config.seed)
        self._target = torch.zeros(self.num_envs, 2)
        self._length = torch.zeros(self.num_envs, dtype=torch.int64)
        self._return = torch.zeros(self.num_envs)
        self._hits = torch.zeros(self.num_envs)

    def aid_metrics(self) -> dict[str, torch.Tensor]:
        return {}  # no training aids

    def _obs(self) -> dict[str, torch.Tensor]:
        return {"proprio": self._target.repeat(1, self.config.frame_stack)}

    def _draw(self, n: int) -> torch.Tensor:
        return torch.rand(n, 2, generator=self._generator) * 2.0 - 1.0

    def reset(self, seed: int | None = None) -> tuple[dict[str, torch.Tensor], dict[str, Any]]:
        if seed is not None:
            self._generator.manual_seed(seed)
        self._target = self._draw(self.num_envs)
        self._length.zero_()
        self._return.zero_()
        self._hits.zero_()
        return self._obs(), {}

    def step(
        self, action: torch.Tensor
    ) -> tuple[dict[str, torch.Tensor], torch.Tensor, torch.Tensor, torch.Tensor, dict]:
        error = (action.clamp(-1, 1) - self._target).square().sum(-1)
        reward = 1.0 - 0.5 * error
        self._return += reward
        self._hits += (error < 0.05).float()
        self._length += 1
        truncated = self._length >= EPISODE_STEPS
        terminated = torch.zeros_like(truncated)
        info: dict[str, Any] = {}
        if bool(truncated.any()):
            info["_episode"] = truncated.clone()
            info["episode"] = {"r": self._return.clone(), "l": self._length.clone(), "hits": self._hits.clone()}
            info["final_obs"] = self._obs()
            self._length[truncated] = 0
            self._return[truncated] = 0.0
            self._hits[truncated] = 0.0
        self._target = self._draw(self.num_envs)
        return self._obs(), reward, terminated, truncated, info

    def state_dict(self) -> dict[str, Any]:
        return {
            "generator": self._generator.get_state(),
            "target": self._target.clone(),
            "length": self._length.clone(),
            "return": self._return.clone(),
            "hits": self._hits.clone(),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self._generator.set_state(state["generator"])
        self._target, self._length = state["target"].clone(), state["length"].clone()
        self._return, self._hits = state["return"].clone(), state["hits"].clone()

    def close(self) -> None:
        pass

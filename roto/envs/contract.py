"""What learners and evaluation may use of a batched env: roto's env contract (as RSL-RL's
``VecEnv``). ``RotoEnv`` keeps it; a test env (``tests/rl/toy_env.py``) keeps it too, so the
trainer, the evaluators and the wrappers never depend on more than this."""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import torch

from roto.envs.config import EnvConfig

Obs = dict[str, torch.Tensor]
"""One (B, k·dim) tensor per observation group."""


@runtime_checkable
class BatchedEnv(Protocol):
    """B worlds stepped together, torch in and out, same-step auto-reset.

    Attributes:
        config: what the env was built from (task, robot, obs mode, counts, seed ...).
        num_envs: B.
        num_actions: the action dimension n; actions are (B, n) in [-1, 1].
        device: where every tensor it takes and returns lives.
        frame_sizes: {group: size of one frame}; observations stack ``config.frame_stack`` of them.
        task: the task (its ``headline_metric``, ``metric_names`` ...).
    """

    config: EnvConfig
    num_envs: int
    num_actions: int
    device: torch.device
    frame_sizes: dict[str, int]
    task: Any

    def reset(self, seed: int | None = None) -> tuple[Obs, dict[str, Any]]:
        """Reset every world: (observations, info)."""
        ...

    def step(self, action: torch.Tensor) -> tuple[Obs, torch.Tensor, torch.Tensor, torch.Tensor, dict[str, Any]]:
        """(obs, reward (B,), terminated (B,), truncated (B,), info); finished worlds reset within."""
        ...

    def state_dict(self) -> dict[str, Any]:
        """Everything that decides the env's future (an exact resume)."""
        ...

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what ``state_dict`` returned."""
        ...

    def aid_metrics(self) -> dict[str, torch.Tensor]:
        """The training aids' scalars to log (empty without aids)."""
        ...

    def close(self) -> None:
        """Release the backend."""
        ...

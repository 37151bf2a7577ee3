"""roto's batched env as an skrl (2.1) torch ``Wrapper``: ``pip install -e '.[skrl]'``.

    from skrl.trainers.torch import SequentialTrainer
    env = SkrlWrapper(roto.make("bounce", robot="shadow", num_envs=64, extra_groups=("privileged",)))
    agent = PPO(models=..., memory=..., observation_space=env.observation_space,
                state_space=env.state_space, action_space=env.action_space, device=env.device, cfg=...)
    SequentialTrainer(env=env, agents=agent, cfg={"timesteps": 100_000, "headless": True}).train()

What skrl gets from roto, one call of the batched env per step, torch on the env's device:

- observations (B, n) float32: the obs mode's groups concatenated in roto's group order
  (``tactile``, ``proprio``, ``privileged``; each (B, k·dim), oldest frame first);
  ``observation_space`` is the matching ``Box`` (n,);
- states (``state()``, what skrl's models get as ``inputs["states"]``, for a critic that reads more
  than the policy): the observation followed by the groups the env returns beyond its obs mode
  (``extra_groups``, in the same order), so a blind env made with ``extra_groups=("privileged",)``
  gives a privileged critic; ``None``, with ``state_space`` ``None``, when the env returns no extra group;
- rewards (B, 1) float32, terminated and truncated (B, 1) bool; truncated means the episode hit its
  time limit without terminating. A finished world is already reset, as in roto's env, so the
  step's observation is the first of its next episode (as with Isaac Lab; skrl's
  ``time_limit_bootstrap`` bootstraps truncated episodes with the value of that observation);
- ``info``: roto's, except that ``info["episode"]``, on steps where episodes ended, holds scalar
  means over those episodes (``Episode / return``, ``length``, ``time-out share``, the task's
  metrics and per-term reward sums), which skrl's trainer logs (it reads the one-element tensors of
  ``info[environment_info]``, ``"episode"`` by default).

``reset()`` resets the worlds the first time only and afterwards returns the latest observation,
as skrl's wrappers of auto-resetting vector envs do (its trainer calls ``reset()`` at the start of
every ``train()`` and ``eval()``). The reset noise is seeded by ``roto.make(seed=...)``, not by
skrl's ``set_seed``.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
import torch

try:
    from skrl.envs.wrappers.torch import Wrapper
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError("roto.wrappers.skrl needs skrl: pip install -e '.[skrl]'") from error

from roto.envs.episodes import EPISODE_NAMES
from roto.envs.observations import OBS_MODES
from roto.envs.roto_env import RotoEnv
from roto.wrappers.wrapped_env import require_roto_env

_LOG_NAMES = {**EPISODE_NAMES, "time_out": "time-out share"}
"""roto's short episode-info keys, spelled out for skrl's log (other keys keep their names)."""


class SkrlWrapper(Wrapper):
    """``env``'s B worlds as one skrl single-agent env; groups concatenated as the module docstring says."""

    def __init__(self, env: RotoEnv) -> None:
        super().__init__(require_roto_env(env, "SkrlWrapper"))
        mode = OBS_MODES[env.config.obs_mode]
        self.policy_groups = tuple(group for group in env.groups if group in mode)
        extra = tuple(group for group in env.groups if group not in mode)
        self.state_groups = self.policy_groups + extra if extra else ()
        self._observation_space = _box(env, self.policy_groups)
        self._state_space = _box(env, self.state_groups) if extra else None
        self._observations: torch.Tensor | None = None
        self._states: torch.Tensor | None = None
        self._info: dict[str, Any] = {}

    @property
    def observation_space(self) -> gymnasium.spaces.Box:
        """One world's policy observation: ``Box`` (n,) float32, n the summed sizes of ``policy_groups``."""
        return self._observation_space

    @property
    def state_space(self) -> gymnasium.spaces.Box | None:
        """One world's state (``state_groups``), or None when the env returns no group beyond its obs mode."""
        return self._state_space

    @property
    def action_space(self) -> gymnasium.spaces.Box:
        """One world's action: ``Box`` [-1, 1]^num_actions float32."""
        return self._env.action_space

    def reset(self) -> tuple[torch.Tensor, dict[str, Any]]:
        """Reset every world on the first call; returns (observations (B, n), info)."""
        if self._observations is None:
            obs, self._info = self._env.reset()
            self._observe(obs)
        return self._observations, self._info

    def step(self, actions: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor, Any]:
        """Step all B worlds with ``actions`` (B, num_actions) on the env's device.

        Returns (observations (B, n), rewards (B, 1), terminated (B, 1), truncated (B, 1), info).
        """
        obs, reward, terminated, truncated, info = self._env.step(actions)
        self._observe(obs)
        self._info = _summarise_episodes(info)
        return self._observations, reward.view(-1, 1), terminated.view(-1, 1), truncated.view(-1, 1), self._info

    def state(self) -> torch.Tensor | None:
        """The latest state (B, s) (``state_groups`` concatenated), or None without extra groups."""
        return self._states

    def render(self, *args: Any, **kwargs: Any) -> None:
        """Nothing to draw: the batched env has no viewer (``roto.eval.video`` records episodes)."""
        return None

    def close(self) -> None:
        """Close the env (releases its backend's threads)."""
        self._env.close()

    def _observe(self, obs: dict[str, torch.Tensor]) -> None:
        """Keep the step's observations and states from the env's groups ((B, k·dim) each)."""
        self._observations = torch.cat([obs[group] for group in self.policy_groups], dim=-1)
        if self.state_groups:
            self._states = torch.cat([obs[group] for group in self.state_groups], dim=-1)


def _box(env: RotoEnv, groups: tuple[str, ...]) -> gymnasium.spaces.Box:
    """Unbounded float32 ``Box`` (n,) for ``groups`` concatenated, n = sum of their stacked sizes."""
    size = sum(env.observation_space[group].shape[0] for group in groups)
    return gymnasium.spaces.Box(-np.inf, np.inf, (size,), np.float32)


def _summarise_episodes(info: dict[str, Any]) -> dict[str, Any]:
    """``info`` with roto's per-world ``episode`` dict ((B,) each, valid where ``_episode``) replaced by
    the means over the episodes that ended this step, 0-d float32 tensors, or dropped if none ended.

    skrl's trainer logs only one-element tensors of ``info["episode"]``, so per-world rows would be
    skipped. Asking whether any episode ended reads the device; skrl's agents read it every step anyway.
    """
    summary = {key: value for key, value in info.items() if key != "episode"}
    ended = info.get("_episode")
    if "episode" not in info or not bool(ended.any()):
        return summary
    count = ended.sum()
    # torch.where, not a product with the mask: a running value that is not finite must not leak in
    summary["episode"] = {
        f"Episode / {_LOG_NAMES.get(name, name)}": torch.where(ended, value.to(torch.float32), 0.0).sum() / count
        for name, value in info["episode"].items()
    }
    return summary

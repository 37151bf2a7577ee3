"""roto's batched env as a Stable-Baselines3 ``VecEnv``: ``pip install -e '.[sb3]'``.

    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor
    venv = VecMonitor(Sb3VecEnv(roto.make("bounce", robot="shadow", num_envs=64)))
    PPO("MultiInputPolicy", venv).learn(100_000)

SB3 steps all B worlds with one call of the batched env (no per-world Gymnasium loop). Observations
are a dict of numpy arrays, one per observation group, (B, k·dim) each. A finished world is reset
within the step, as roto's env does; its last observation goes to ``infos[i]["terminal_observation"]``
and ``infos[i]["TimeLimit.truncated"]`` says whether the episode ended by its time limit, which is
what SB3's PPO bootstraps on. ``VecMonitor`` adds SB3's episode statistics.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import torch

try:
    from stable_baselines3.common.vec_env import VecEnv
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError("roto.wrappers.sb3 needs Stable-Baselines3: pip install -e '.[sb3]'") from error

from roto.envs.roto_env import RotoEnv
from roto.wrappers.wrapped_env import require_roto_env


class Sb3VecEnv(VecEnv):
    """``env``'s B worlds as an SB3 ``VecEnv`` (numpy in and out, torch inside on the env's device)."""

    def __init__(self, env: RotoEnv) -> None:
        env = require_roto_env(env, "Sb3VecEnv")
        self.env = env
        self._actions: torch.Tensor | None = None
        super().__init__(env.num_envs, env.observation_space, env.action_space)

    def reset(self) -> dict[str, np.ndarray]:
        """Reset every world; a seed given through ``seed()`` re-seeds the reset noise."""
        obs, _ = self.env.reset(seed=self._seeds[0])
        self._reset_seeds()
        return _numpy(obs)

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = torch.as_tensor(np.asarray(actions, dtype=np.float32), device=self.env.device)

    def step_wait(self) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, list[dict[str, Any]]]:
        obs, reward, terminated, truncated, info = self.env.step(self._actions)
        done = (terminated | truncated).cpu().numpy()
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        finished = np.flatnonzero(done)
        if len(finished):  # one host copy of the finished rows, then per finished world only
            final = {name: value.cpu().numpy()[finished] for name, value in info["final_obs"].items()}
            time_limit = (truncated & ~terminated).cpu().numpy()
            for row, world in enumerate(finished):
                infos[world]["terminal_observation"] = {name: value[row] for name, value in final.items()}
                infos[world]["TimeLimit.truncated"] = bool(time_limit[world])
        return _numpy(obs), reward.cpu().numpy(), done, infos

    def close(self) -> None:
        self.env.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        """The env's attribute once per selected world (roto's worlds share one env object)."""
        value = None if attr_name == "render_mode" else getattr(self.env, attr_name)
        return [value for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        raise AttributeError(
            f"cannot set {attr_name!r} per world: roto's {self.num_envs} worlds share one env; set it on `.env`"
        )

    def env_method(self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any) -> list[Any]:
        raise AttributeError(
            f"cannot call {method_name!r} per world: roto's {self.num_envs} worlds share one env; call it on `.env`"
        )

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> Sequence[bool]:
        return [False for _ in self._get_indices(indices)]


def _numpy(obs: dict[str, torch.Tensor]) -> dict[str, np.ndarray]:
    return {name: value.cpu().numpy() for name, value in obs.items()}

"""Gymnasium adapters: a ``VectorEnv`` (numpy, same-step autoreset) and a single ``Env``.

Both wrap ``RotoEnv``; observations are ``Dict`` spaces with one ``Box`` per group.
"""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
import torch
from gymnasium.vector.utils import batch_space

from roto.envs.roto_env import RotoEnv
from roto.envs.single_world import SingleWorldStep, single_world_result, supports_single_world_step
from roto.registry import check_id_pair, make


def _to_numpy(tree: Any) -> Any:
    if isinstance(tree, torch.Tensor):
        return tree.detach().cpu().numpy()
    if isinstance(tree, dict):
        return {k: _to_numpy(v) for k, v in tree.items()}
    return tree


def _action_tensor(action: Any, env: RotoEnv) -> torch.Tensor:
    array = np.asarray(action)
    if not np.issubdtype(array.dtype, np.floating):
        raise TypeError(f"action dtype {array.dtype} is not floating point; use float32 or float64")
    return torch.as_tensor(array, device=env.device)


class RotoVectorEnv(gym.vector.VectorEnv):
    """``num_envs`` roto worlds as a Gymnasium ``VectorEnv`` (autoreset mode SAME_STEP).

    Finished sub-envs are reset inside ``step``; their last observation is in
    ``info["final_obs"]`` (one dict per finished env, ``None`` elsewhere), as Gymnasium's
    same-step convention prescribes, and episode statistics in ``info["episode"]``.
    """

    metadata: ClassVar[dict[str, Any]] = {"autoreset_mode": gym.vector.AutoresetMode.SAME_STEP, "render_modes": []}

    def __init__(self, task: str, robot: str, num_envs: int = 1, env_id: str | None = None, **kwargs: Any) -> None:
        if env_id is not None:  # made through a Gymnasium id: the id fixes the pair
            check_id_pair(env_id, task, robot)
        self.env = make(task, robot=robot, num_envs=num_envs, **kwargs)
        self.num_envs = num_envs
        self.single_observation_space = self.env.observation_space
        self.single_action_space = self.env.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Any, dict]:
        """Reset every sub-env (``seed`` re-seeds the reset noise)."""
        obs, info = self.env.reset(seed=seed)
        return _to_numpy(obs), info

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict]:
        """One control step of every sub-env; numpy in, numpy out."""
        obs, reward, terminated, truncated, info = self.env.step(_action_tensor(actions, self.env))
        out_info = _to_numpy({k: v for k, v in info.items() if k not in ("final_obs", "_final_obs")})
        if "final_obs" in info:
            final = _to_numpy(info["final_obs"])
            mask = info["_final_obs"].cpu().numpy()
            objects = np.full(self.num_envs, None, dtype=object)
            for i in np.flatnonzero(mask):
                objects[i] = {k: v[i] for k, v in final.items()}
            out_info["final_obs"] = objects
            out_info["_final_obs"] = mask
        return _to_numpy(obs), reward.numpy(), terminated.numpy(), truncated.numpy(), out_info

    def close_extras(self, **kwargs: Any) -> None:
        """Release the physics threads."""
        self.env.close()


class RotoSingleEnv(gym.Env):
    """One roto world as a plain Gymnasium ``Env`` (for ``gymnasium.make`` and its checker)."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": []}

    def __init__(self, task: str, robot: str, env_id: str | None = None, num_envs: int = 1, **kwargs: Any) -> None:
        if env_id is not None:  # made through a Gymnasium id: the id fixes the pair
            check_id_pair(env_id, task, robot)
        if num_envs != 1:
            raise ValueError(
                f"num_envs={num_envs!r}: a single Gymnasium env is one world; for N worlds use "
                "gymnasium.make_vec(id, num_envs=N, vectorization_mode='vector_entry_point')"
            )
        self.env = make(task, robot=robot, num_envs=1, **kwargs)
        self.observation_space = self.env.observation_space
        self.action_space = self.env.action_space
        # numpy glue around the task's rule where the env allows it: the same trajectories, faster
        self._fast_step = SingleWorldStep(self.env) if supports_single_world_step(self.env) else None

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Any, dict]:
        """Start a new episode."""
        super().reset(seed=seed)
        obs, _ = self.env.reset(seed=seed)
        return {k: v.numpy()[0] for k, v in obs.items()}, {}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict]:
        """One control step; at the end of an episode returns the episode's last observation."""
        if self._fast_step is not None:
            return self._fast_step.step(action)
        return single_world_result(*self.env.step(_action_tensor(action, self.env).reshape(1, -1)))

    def close(self) -> None:
        """Release the physics threads."""
        self.env.close()

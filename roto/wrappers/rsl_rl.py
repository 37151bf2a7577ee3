"""roto's batched env as an RSL-RL ``VecEnv`` (rsl-rl-lib 5.5): ``pip install -e '.[rsl_rl]'``.

    from rsl_rl.runners import OnPolicyRunner
    env = roto.make("bounce", robot="shadow", num_envs=4096, extra_groups=("privileged",))
    cfg = {..., "obs_groups": {"actor": ["proprio", "tactile"], "critic": ["proprio", "tactile", "privileged"]}}
    OnPolicyRunner(RslRlVecEnv(env), cfg, log_dir="runs/rsl_rl").learn(1500)

What RSL-RL gets from roto, one call of the batched env per step, torch on the env's device:

- observations: a ``TensorDict`` (batch size B) of the env's groups under their own names
  (``proprio``, ``tactile``, ``privileged``; (B, k·dim) float32 each); the runner's ``obs_groups``
  picks which groups the actor and the critic read, so an env made with
  ``extra_groups=("privileged",)`` gives a blind actor and a privileged critic;
- rewards (B,) float32; dones (B,) int64, terminated or truncated (the world is already reset, as
  in roto's env);
- ``extras["time_outs"]`` (B,) bool: the episode hit its time limit without terminating, which
  RSL-RL's PPO bootstraps with the value of the step's observation;
- ``extras["log"]``, on steps where episodes ended: roto's statistics of those episodes (return,
  length, time-out share, task metrics, per-term reward sums), one value per ended episode under
  ``Episode/``, averaged per iteration by RSL-RL's logger;
- ``max_episode_length`` (control steps) and ``episode_length_buf`` (B,) int64, steps so far.
"""

from __future__ import annotations

from typing import Any

import torch

try:
    from rsl_rl.env import VecEnv
    from tensordict import TensorDict
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError("roto.wrappers.rsl_rl needs RSL-RL: pip install -e '.[rsl_rl]'") from error

from roto.envs.config import EnvConfig
from roto.envs.episodes import EPISODE_NAMES
from roto.envs.roto_env import RotoEnv
from roto.wrappers.wrapped_env import require_roto_env

_LOG_NAMES = EPISODE_NAMES
"""roto's short episode-info keys, spelled out for RSL-RL's log (other keys keep their names)."""


class RslRlVecEnv(VecEnv):
    """``env``'s B worlds as an RSL-RL ``VecEnv``; resets the env once, as RSL-RL's runner never does."""

    def __init__(self, env: RotoEnv) -> None:
        env = require_roto_env(env, "RslRlVecEnv")
        self.env = env
        self.num_envs = env.num_envs
        self.num_actions = env.num_actions
        self.device = env.device
        self.max_episode_length = env.config.episode_steps
        self._lengths = torch.zeros(self.num_envs, dtype=torch.int64, device=self.device)
        # RSL-RL's runner reads observations before its first step and has no reset call
        with torch.inference_mode(False):
            obs, _ = env.reset()
        self._obs = self._tensordict(obs)

    @property
    def cfg(self) -> EnvConfig:
        """The env's config (RSL-RL's W&B and Neptune writers store it with the run)."""
        return self.env.config

    @property
    def episode_length_buf(self) -> torch.Tensor:
        """(B,) int64 control steps of each world's current episode."""
        return self._lengths

    @episode_length_buf.setter
    def episode_length_buf(self, value: torch.Tensor) -> None:
        # RSL-RL writes it for `learn(init_at_random_ep_len=True)`: roto's episodes always start at
        # step 0, so a silently ignored write would let the run believe its time-outs are staggered
        raise AttributeError(
            "roto's episodes cannot start part-way through: call runner.learn(..., init_at_random_ep_len=False)"
        )

    def get_observations(self) -> TensorDict:
        """The current observation groups, (B, k·dim) each."""
        return self._obs

    def step(self, actions: torch.Tensor) -> tuple[TensorDict, torch.Tensor, torch.Tensor, dict[str, Any]]:
        """Step every world with ``actions`` (B, num_actions); returns (obs, rewards (B,), dones (B,), extras)."""
        # RSL-RL steps under torch.inference_mode; the env's state made there would become inference
        # tensors that the env's in-place updates then reject outside it (evaluation after training).
        # The env is not differentiable: no_grad keeps a policy's graph out of its state
        with torch.inference_mode(False), torch.no_grad():
            obs, reward, terminated, truncated, info = self.env.step(actions)
            done = terminated | truncated
            self._lengths = (self._lengths + 1).masked_fill(done, 0)
            self._obs = self._tensordict(obs)
            extras: dict[str, Any] = {"time_outs": truncated}
            log = _episode_log(info)
            if log:
                extras["log"] = log
        return self._obs, reward, done.long(), extras

    def close(self) -> None:
        """Release the env's threads."""
        self.env.close()

    def _tensordict(self, obs: dict[str, torch.Tensor]) -> TensorDict:
        return TensorDict(obs, batch_size=[self.num_envs], device=self.device)


def _episode_log(info: dict[str, Any]) -> dict[str, torch.Tensor]:
    """roto's statistics of the episodes that ended this step, ``Episode/<name>`` -> (n_ended,) float32
    (one value each, so RSL-RL's per-iteration mean weighs every episode alike); empty if none ended."""
    if "episode" not in info:
        return {}
    # a GPU env reports episode info every step, masked; finding the ended worlds reads the device
    # once (RSL-RL's logger reads the dones every step anyway)
    ended = info["_episode"].nonzero().squeeze(1)
    if len(ended) == 0:
        return {}
    return {
        f"Episode/{_LOG_NAMES.get(name, name)}": value.index_select(0, ended).to(torch.float32)
        for name, value in info["episode"].items()
    }

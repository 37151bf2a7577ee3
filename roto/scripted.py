"""A scripted Bounce policy that reads the ball state, and a runner for it.

The policy holds the hand in its cupped default pose and swings the wrist (flexion joint) up while
the ball is on the palm and not yet rising fast, or falling towards it; otherwise it swings down.
It is a reference for what this hand can do, not a learned agent: see docs/robots.md for the
figures it reaches.
"""

from __future__ import annotations

import torch
from tqdm import tqdm

from roto.envs.roto_env import RotoEnv
from roto.registry import make


class ScriptedBounce:
    """Bang-bang wrist policy for Bounce on a robot whose actuated joints include a wrist flexion joint.

    Args:
        env: a Bounce env built with ``obs_mode="state"`` (the policy reads the ball state and touch).
        wrist_joint: name of the flexion joint that swings the palm up (positive = palm up).
        up, down: wrist targets (rad) for the strike and the return.
        launch_speed: keep pushing while the touching ball rises slower than this (m/s).
        trigger_height: strike when the falling ball's centre is below this height (m).
    """

    def __init__(
        self,
        env: RotoEnv,
        wrist_joint: str,
        *,
        up: float = 0.489,
        down: float = -0.65,
        launch_speed: float = 0.6,
        trigger_height: float = 0.04,
    ) -> None:
        if "privileged" not in env.groups or "tactile" not in env.groups:
            raise ValueError(f"the scripted policy needs obs_mode='state', got {env.config.obs_mode!r}")
        idx = env._idx
        self._lo, self._hi = idx.ctrl_lo, idx.ctrl_hi
        self._base = idx.default_qpos[0, idx.act_qpos]
        self._wrist = env.robot.actuated_joints.index(wrist_joint)
        self._n_links = env.frame_sizes["tactile"]
        self._n_priv = env.frame_sizes["privileged"]
        self.up, self.down, self.launch_speed, self.trigger_height = up, down, launch_speed, trigger_height

    def __call__(self, obs: dict[str, torch.Tensor]) -> torch.Tensor:
        """Actions (B, n) in [-1, 1] from the latest frame of ``obs``."""
        ball = obs["privileged"][:, -self._n_priv :].to(torch.float64)
        height, rise = ball[:, 2], ball[:, 5]
        touching = obs["tactile"][:, -self._n_links :].sum(dim=1) > 0
        strike = (touching & (rise < self.launch_speed)) | (~touching & (rise < 0) & (height < self.trigger_height))
        target = self._base.expand(len(ball), -1).clone()
        target[:, self._wrist] = torch.where(strike, self.up, self.down)
        return (2.0 * (target - self._lo) / (self._hi - self._lo) - 1.0).to(torch.float32)


def run_scripted_bounce(
    robot: str = "shadow", num_envs: int = 8, seed: int = 0, episodes: int = 1, progress: bool = False
) -> dict[str, float]:
    """Run the scripted policy until ``episodes`` episodes per env have finished; bounce statistics."""
    env = make("bounce", robot=robot, num_envs=num_envs, obs_mode="state", seed=seed)
    policy = ScriptedBounce(env, wrist_joint=env.robot.actuated_joints[1])
    obs, _ = env.reset()
    bounces: list[float] = []
    lengths: list[float] = []
    target = episodes * num_envs
    with tqdm(total=target, disable=not progress, desc="scripted bounce episodes") as bar:
        while len(bounces) < target:
            obs, _, _, _, info = env.step(policy(obs))
            if "episode" in info:
                done = info["_episode"]
                bounces += info["episode"]["bounces"][done].tolist()
                lengths += info["episode"]["l"][done].tolist()
                bar.update(int(done.sum()))
    env.close()
    bounces, lengths = bounces[:target], lengths[:target]
    return {
        "episodes": len(bounces),
        "mean_bounces": sum(bounces) / len(bounces),
        "max_bounces": max(bounces),
        "mean_length": sum(lengths) / len(lengths),
    }

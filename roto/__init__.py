"""roto: the Robot Tactile Olympiad on MuJoCo.

import roto
env = roto.make("bounce", robot="shadow", num_envs=256, obs_mode="blind")
obs, info = env.reset()
obs, reward, terminated, truncated, info = env.step(action)
"""

from __future__ import annotations

from roto.registry import list_envs, make, register_gymnasium_envs

__all__ = ["list_envs", "make", "register_gymnasium_envs"]
__version__ = "0.1.0"

register_gymnasium_envs()

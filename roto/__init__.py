"""roto: the Robot Tactile Olympiad on MuJoCo.

import roto
env = roto.make("bounce", robot="shadow", num_envs=256, obs_mode="blind")
obs, info = env.reset()
obs, reward, terminated, truncated, info = env.step(action)
"""

from __future__ import annotations

import os
import sys

if sys.platform.startswith("linux") and not os.environ.get("DISPLAY") and not os.environ.get("MUJOCO_GL"):
    # Headless Linux: MuJoCo's offscreen renderer needs EGL (Mesa works on a CPU). Must be set
    # before mujoco is first imported; an explicit MUJOCO_GL (e.g. osmesa) always wins.
    os.environ["MUJOCO_GL"] = "egl"

from roto.registry import list_envs, make, register_gymnasium_envs

__all__ = ["list_envs", "make", "register_gymnasium_envs"]
__version__ = "0.1.0"

register_gymnasium_envs()

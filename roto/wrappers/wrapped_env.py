"""What the learning libraries' adapters wrap: one batched roto env, checked so that a wrong object
is one clear error, not an AttributeError from inside an adapter."""

from __future__ import annotations

from typing import Any

from roto.envs.roto_env import RotoEnv


def require_roto_env(env: Any, adapter: str) -> RotoEnv:
    """``env`` if it is a batched roto env (``roto.make``); else TypeError naming ``adapter``, what it
    wraps and what it was given (a Gymnasium env of ``gymnasium.make``/``make_vec`` is not one)."""
    if isinstance(env, RotoEnv):
        return env
    raise TypeError(
        f"{adapter} wraps a batched roto env, roto.make(task, robot=..., num_envs=N), got {type(env).__name__} "
        f"({env!r:.80}); a Gymnasium env from gymnasium.make or make_vec is not one: give the roto env itself"
    )

"""One override syntax for a run's envs and its agent: ``section.key=value``.

``env.<field>=value`` changes the training envs' config (``EnvConfig``, e.g. ``env.num_envs=64``);
every other section is the agent config's (``network``, ``ppo``, ``ssl``, ``run``, e.g.
``ppo.lr=1e-4``). Values are parsed as YAML. ``roto train`` and ``roto sweep`` read both kinds.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from roto.envs.config import EnvConfig
from roto.rl.config import parse_override

ENV_SECTION = "env"
FIXED_ENV_KEYS = ("task", "robot", "obs_mode", "extra_groups")
"""Env fields no override sets: what the run is (task, robot, obs mode) and what the learner reads
besides the policy's groups."""


def env_override_keys() -> list[str]:
    """The ``env.<key>`` names an override may set."""
    return [f.name for f in dataclasses.fields(EnvConfig) if f.name not in FIXED_ENV_KEYS]


def split_overrides(items: list[str]) -> tuple[dict[str, Any], list[str]]:
    """({env field: value}, agent overrides) from a mixed list of ``section.key=value`` strings."""
    env: dict[str, Any] = {}
    agent: list[str] = []
    for item in items:
        key, value = parse_override(item)
        section, _, leaf = key.partition(".")
        if section != ENV_SECTION:
            agent.append(item)
            continue
        if leaf not in env_override_keys():
            raise ValueError(f"override {item!r}: unknown env key {leaf!r}; valid env keys: {env_override_keys()}")
        env[leaf] = value
    return env, agent


def apply_env_overrides(env: EnvConfig, changes: dict[str, Any]) -> EnvConfig:
    """``env`` with ``changes`` ({field: value}); EnvConfig checks the values."""
    return dataclasses.replace(env, **changes)

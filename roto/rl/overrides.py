"""One override syntax for a run's envs and its agent: ``section.key=value``.

``env.<field>=value`` changes the training envs' config (``EnvConfig``, e.g. ``env.num_envs=64``),
``env.aids.<aid>.<setting>=value`` one setting of a training aid (switching the aid on;
``env.aids.<aid>=null`` switches it off; ``roto.envs.aids.settings``); every other section is
the agent config's (``network``, ``ppo``, ``ssl``, ``run``, e.g. ``ppo.lr=1e-4``). Values are
parsed as YAML. ``roto train`` and ``roto sweep`` read both kinds.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from roto.envs.aids.settings import LEGACY_FIELDS
from roto.envs.config import EnvConfig
from roto.rl.config_files import TRAINING_AIDS, merge, parse_override

AIDS = "aids"

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
        if section == TRAINING_AIDS:  # an agent config's section, whose aids the envs carry
            raise ValueError(
                f"override {item!r}: a config's {TRAINING_AIDS} are the envs' aids; "
                f"on the command line: {'.'.join(('env', AIDS, leaf) if leaf else ('env', AIDS))}=..."
            )
        if section != ENV_SECTION:
            agent.append(item)
            continue
        if leaf in LEGACY_FIELDS:
            new = "env.aids." + ".".join(LEGACY_FIELDS[leaf])
            raise ValueError(f"override {item!r}: training aids are set per aid now: {new}=...")
        name, _, rest = leaf.partition(".")
        if name not in env_override_keys() or (rest and name != AIDS):
            raise ValueError(f"override {item!r}: unknown env key {leaf!r}; valid env keys: {env_override_keys()}")
        if rest:  # env.aids.<aid>[.<setting>]
            set_nested(env.setdefault(AIDS, {}), rest.split("."), value)
        else:
            env[name] = merge(env[name], value) if name == AIDS and isinstance(env.get(name), dict) else value
    return env, agent


def set_nested(section: dict[str, Any], keys: list[str], value: Any) -> None:
    """``section[k1][k2]... = value``, making the mappings on the way."""
    for key in keys[:-1]:
        if not isinstance(section.get(key), dict):
            section[key] = {}
        section = section[key]
    section[keys[-1]] = value


def apply_env_overrides(env: EnvConfig, changes: dict[str, Any]) -> EnvConfig:
    """``env`` with ``changes`` ({field: value}; an ``aids`` mapping merges into ``env``'s aids
    setting by setting, an aid mapped to None is switched off); EnvConfig checks the values."""
    if isinstance(changes.get(AIDS), dict):
        changes = {**changes, AIDS: merge(env.aids.to_dict(), changes[AIDS])}
    return dataclasses.replace(env, **changes)

"""What a training run is, built one way for every caller: ``roto train``, sweep trials and
Olympiad cells.

``build_run_spec`` turns a task, a robot, an obs mode, an agent config and ``section.key=value``
overrides into a ``RunSpec``: ``env.<field>=value`` sets any env field but the task, robot, obs mode
and the learner's extra groups (backend, device, seed, touch, num_envs, replayed starts ...); every
other override changes the agent config. ``roto.rl.runner.Trainer.open`` then creates the run, or
continues it when it already has a checkpoint.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from roto.envs.aids.settings import aids_from_legacy_fields
from roto.envs.config import EnvConfig
from roto.envs.replay_starts import check_replay_starts
from roto.rl.config import AgentConfig, from_dict, to_dict
from roto.rl.config_files import load_agent_config, load_training_aids
from roto.rl.overrides import apply_env_overrides, split_overrides
from roto.robots import get_robot
from roto.tasks import get_task

DEFAULT_STEPS = 1_000_000
EXECUTION_KEYS = ("env.threads",)
"""Spec keys that say how fast a run trains, not what: a run continues under other values."""


@dataclass(frozen=True, kw_only=True)
class RunSpec:
    """A training run: its training envs, its agent and its env-step budget. What a run's
    ``config.yaml`` holds (``roto.rl.run_config``), what checkpoints carry and what a trainer is
    built from."""

    env: EnvConfig
    agent: AgentConfig = field(default_factory=AgentConfig)
    """Default: roto's PPO as ``AgentConfig`` defines it."""
    steps: int = DEFAULT_STEPS

    def __post_init__(self) -> None:
        """A budget below one env step is an error."""
        if isinstance(self.steps, bool) or not isinstance(self.steps, int) or self.steps < 1:
            raise ValueError(f"the step budget must be an integer >= 1, got {self.steps!r}")

    def env_config(self, num_envs: int | None = None, seed: int | None = None, **changes: Any) -> EnvConfig:
        """The training envs' config, or that of other envs (another num_envs / seed / backend ...)."""
        changes.update({name: value for name, value in (("num_envs", num_envs), ("seed", seed)) if value is not None})
        return dataclasses.replace(self.env, **changes)

    def eval_env_config(self, num_envs: int | None = None, seed: int | None = None, **changes: Any) -> EnvConfig:
        """As ``env_config``, without training aids (``EnvConfig.without_training_aids``): evaluation
        is always the benchmark's own task."""
        return self.env_config(num_envs, seed, **changes).without_training_aids()

    def cpu_env_config(self, num_envs: int | None = None, seed: int | None = None, **changes: Any) -> EnvConfig:
        """As ``eval_env_config``, on the CPU backend: evaluation and videos of any run, GPU-trained too."""
        return self.eval_env_config(num_envs, seed, backend="cpu", device="cpu", **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain nested dict of builtins: {"env", "agent", "steps"} (config.yaml, checkpoints)."""
        env = dataclasses.asdict(self.env)
        env["extra_groups"] = list(env["extra_groups"])
        env["aids"] = self.env.aids.to_dict()  # the aids that are on
        return {"env": env, "agent": to_dict(self.agent), "steps": self.steps}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> RunSpec:
        """Inverse of ``to_dict``; a stored spec of an older layout (``spec_data``) is read too."""
        data = spec_data(data)
        env = EnvConfig(**aids_from_legacy_fields(data["env"]))
        return cls(env=env, agent=from_dict(AgentConfig, data["agent"]).validate(), steps=int(data["steps"]))

    def with_steps(self, steps: int) -> RunSpec:
        """This run with budget ``steps``."""
        return dataclasses.replace(self, steps=steps)

    def with_seed(self, seed: int) -> RunSpec:
        """This run with env seed ``seed`` (a sweep trial's or an Olympiad cell's own, which wins
        over any ``env.seed`` override)."""
        return dataclasses.replace(self, env=dataclasses.replace(self.env, seed=seed))

    def differences(self, other: RunSpec) -> dict[str, tuple[Any, Any]]:
        """{dotted key: (this value, other's value)} where the two specs train differently. The
        budget and the C threads aside (``EXECUTION_KEYS``): a run may be extended, and continued
        on another number of threads, which step the same worlds to the same states
        (tests/envs/test_determinism.py)."""
        mine = {"env": dataclasses.asdict(self.env), "agent": to_dict(self.agent)}
        theirs = {"env": dataclasses.asdict(other.env), "agent": to_dict(other.agent)}
        pairs = _flat_pairs(mine, theirs).items()
        return {key: pair for key, pair in pairs if pair[0] != pair[1] and key not in EXECUTION_KEYS}


def spec_data(data: dict[str, Any]) -> dict[str, Any]:
    """A stored spec as {"env", "agent", "steps"}: run configs and checkpoints of formats 1 and 2
    held the envs and budget in a ``train`` section ({"env", "total_steps"}) beside ``agent``."""
    if "train" not in data:
        return data
    train = data["train"]
    return {"env": train["env"], "agent": data.get("agent", {}), "steps": train["total_steps"]}


def _flat_pairs(a: dict[str, Any], b: dict[str, Any], prefix: str = "") -> dict[str, tuple[Any, Any]]:
    pairs = {}
    for key in sorted(set(a) | set(b)):
        x, y = a.get(key), b.get(key)
        if isinstance(x, dict) and isinstance(y, dict):
            pairs.update(_flat_pairs(x, y, f"{prefix}{key}."))
        else:
            pairs[f"{prefix}{key}"] = (x, y)
    return pairs


def build_run_spec(
    task: str,
    robot: str = "shadow",
    obs: str = "blind",
    agent_cfg: str | None = None,
    overrides: Sequence[str] = (),
    steps: int = DEFAULT_STEPS,
    **env_fields: Any,
) -> RunSpec:
    """The run ``task`` x ``robot`` x ``obs`` with agent config ``agent_cfg`` (a file, a packaged
    name, or None: the task's default) and ``overrides``.

    ``env_fields`` set env fields directly (the CLI's ``--num_envs``, ``--backend`` ... flags);
    the agent config's ``training_aids`` and then the ``env.*`` overrides are applied after them, so
    an override wins over the config and a flag. Everything is validated here, before any directory
    or env exists.
    """
    task, robot = get_task(task).name, get_robot(robot).name  # any case, as roto.make; a bad name is refused
    env_changes, agent_overrides = split_overrides(list(overrides))
    env = training_env(EnvConfig(task=task, robot=robot, obs_mode=obs, **env_fields), agent_cfg, env_changes)
    agent = load_agent_config(task, agent_cfg, agent_overrides)
    spec = RunSpec(env=env, agent=agent, steps=steps)  # checks the budget
    check_replay_starts(env)  # the bank is read now, not when a run, a plan's cell or a sweep's trial starts
    return spec


def training_env(env: EnvConfig, agent_cfg: str | None, env_changes: dict[str, Any]) -> EnvConfig:
    """The training envs' config: ``env`` with the agent config's ``training_aids`` (for ``env``'s
    task and robot), then ``env_changes`` (the ``env.*`` overrides, which win)."""
    with_aids = apply_env_overrides(env, {"aids": load_training_aids(env.task, agent_cfg, env.robot)})
    return apply_env_overrides(with_aids, env_changes)

"""What a training run trains on, and the run directory's ``config.yaml``."""

from __future__ import annotations

import dataclasses
import pathlib
from dataclasses import dataclass
from typing import Any

import yaml

from roto.artifact_formats import FORMAT_KEY, check_format, format_stamp
from roto.envs.aids.settings import aids_from_legacy_fields
from roto.envs.config import EnvConfig
from roto.result_files import write_text_atomic
from roto.rl.config import AgentConfig, from_dict, to_dict
from roto.yaml_files import read_yaml

CONFIG_NAME = "config.yaml"


@dataclass(frozen=True, kw_only=True)
class TrainSettings:
    """What a training run trains on (the training envs' config) and for how many env steps."""

    env: EnvConfig
    total_steps: int = 1_000_000

    def __post_init__(self) -> None:
        """A budget below one env step is an error."""
        if isinstance(self.total_steps, bool) or not isinstance(self.total_steps, int) or self.total_steps < 1:
            raise ValueError(f"the step budget must be an integer >= 1, got {self.total_steps!r}")

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
        """Plain nested dict of builtins (for config.yaml and checkpoints)."""
        env = dataclasses.asdict(self.env)
        env["extra_groups"] = list(env["extra_groups"])
        env["aids"] = self.env.aids.to_dict()  # the aids that are on
        return {"env": env, "total_steps": self.total_steps}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainSettings:
        """Inverse of ``to_dict``; a format-1 env (aid settings as flat fields) is read into today's."""
        return cls(env=EnvConfig(**aids_from_legacy_fields(data["env"])), total_steps=int(data["total_steps"]))


def run_config(settings: TrainSettings, agent: AgentConfig) -> dict[str, Any]:
    """The resolved config of a run as a plain nested dict: {"train": settings, "agent": agent config}."""
    return {**format_stamp("run config"), "train": settings.to_dict(), "agent": to_dict(agent)}


def write_run_config(run_dir: pathlib.Path, settings: TrainSettings, agent: AgentConfig) -> None:
    """The resolved config of a run (what ``--resume`` reads back)."""
    write_text_atomic(run_dir / CONFIG_NAME, yaml.safe_dump(run_config(settings, agent), sort_keys=False))


def read_run_config(run_dir: pathlib.Path) -> tuple[TrainSettings, AgentConfig]:
    """Inverse of ``write_run_config``."""
    path = run_dir / CONFIG_NAME
    if not path.is_file():
        raise FileNotFoundError(f"{str(run_dir)!r} is not a roto run directory (no {CONFIG_NAME})")
    data = read_yaml(path, "run config")
    if not isinstance(data, dict) or not {"train", "agent"} <= set(data):
        raise ValueError(f"run config {str(path)!r} is not a roto run config (no 'train' and 'agent' sections)")
    check_format("run config", data.get(FORMAT_KEY), f"run config {str(path)!r}")
    return TrainSettings.from_dict(data["train"]), from_dict(AgentConfig, data["agent"]).validate()

"""Search spaces of ``roto sweep``: YAML files of parameters, checked before any trial runs.

A space file has two sections. ``parameters`` maps an override key (``ppo.lr``, ``env.num_envs``:
the ``section.key`` of ``roto train``'s overrides) to a distribution; ``ssl_parameters`` maps a
field of an auxiliary loss (``lr``, ``weight``, ``seq_length`` ...) to one, searched for every
auxiliary loss the base agent config enables that has the field. Distributions::

    {type: int, low: 4, high: 10}                  # optional: log, step
    {type: float, low: 1.0e-5, high: 5.0e-4, log: true}
    {type: categorical, choices: [16, 32, 64]}

The packaged spaces are ``roto2`` (roto 2.0's, the default) and ``roto1`` (the original's released
script), docs/spec.md §8.
"""

from __future__ import annotations

import dataclasses
import importlib.resources
import json
import pathlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import optuna

from roto.envs.config import EnvConfig
from roto.rl.config import AgentConfig, from_dict
from roto.rl.config_files import load_agent_config
from roto.rl.overrides import apply_env_overrides, split_overrides
from roto.rl.run_spec import training_env
from roto.rl.ssl.configs import SSLConfig
from roto.yaml_files import read_yaml

DISTRIBUTION_KEYS = {
    "int": {"type", "low", "high", "log", "step"},
    "float": {"type", "low", "high", "log"},
    "categorical": {"type", "choices"},
}
SPACE_KEYS = ("parameters", "ssl_parameters")


@dataclass(frozen=True)
class Parameter:
    """One searched value: an override key and its distribution."""

    key: str
    type: str
    low: float | None = None
    high: float | None = None
    log: bool = False
    step: int = 1
    choices: tuple[Any, ...] = ()

    def suggest(self, trial: optuna.Trial) -> Any:
        """Draw this parameter's value for ``trial``."""
        if self.type == "int":
            return trial.suggest_int(self.key, int(self.low), int(self.high), log=self.log, step=self.step)
        if self.type == "float":
            return trial.suggest_float(self.key, float(self.low), float(self.high), log=self.log)
        return trial.suggest_categorical(self.key, list(self.choices))

    def extremes(self) -> list[Any]:
        """The values a run must accept for every draw to be usable: the bounds, or every choice."""
        return [self.low, self.high] if self.type != "categorical" else list(self.choices)

    def contains(self, value: Any) -> bool:
        """Whether this parameter's distribution can draw ``value``."""
        if self.type == "categorical":
            return value in self.choices
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not self.low <= value <= self.high:
            return False
        return self.type == "float" or (float(value).is_integer() and (value - self.low) % self.step == 0)


@dataclass(frozen=True)
class SearchSpace:
    """The parameters of a sweep (already expanded over the base config's auxiliary losses)."""

    name: str
    parameters: tuple[Parameter, ...]

    def suggest(self, trial: optuna.Trial) -> dict[str, Any]:
        """{override key: value} drawn for ``trial``."""
        return {p.key: p.suggest(trial) for p in self.parameters}


def base_values(space: SearchSpace, env: EnvConfig, agent: AgentConfig) -> tuple[dict[str, Any], dict[str, Any]]:
    """The base run's value of every searched parameter, split into those its distribution can draw
    and those outside it: ({key: value} inside, {key: value} outside)."""
    tree = {"env": dataclasses.asdict(env), **dataclasses.asdict(agent)}
    inside, outside = {}, {}
    for parameter in space.parameters:
        value: Any = tree
        for part in parameter.key.split("."):
            value = value[part] if isinstance(value, dict) else None  # None: under an aid that is off
        value = list(value) if isinstance(value, tuple) else value
        (inside if parameter.contains(value) else outside)[parameter.key] = value
    return inside, outside


def as_overrides(params: dict[str, Any]) -> list[str]:
    """``section.key=value`` strings of drawn parameters (values written as JSON, which YAML reads)."""
    return [f"{key}={json.dumps(value)}" for key, value in params.items()]


def packaged_spaces() -> dict[str, pathlib.Path]:
    """{name: path} of the search spaces shipped in ``roto/configs/sweep``."""
    folder = importlib.resources.files("roto") / "configs" / "sweep"
    return {pathlib.Path(str(p)).stem: pathlib.Path(str(p)) for p in folder.iterdir() if p.name.endswith(".yaml")}


def resolve_space_path(space: str) -> pathlib.Path:
    """The YAML file ``--space`` means: a file or a packaged space's name."""
    shipped = packaged_spaces()
    if space in shipped:
        return shipped[space]
    if pathlib.Path(space).is_file():
        return pathlib.Path(space)
    raise FileNotFoundError(f"search space {space!r} does not exist; give a YAML file or one of {sorted(shipped)}")


def parse_parameter(key: str, spec: Any, where: str) -> Parameter:
    """A ``Parameter`` from its YAML mapping; ValueError naming ``where`` and the key on bad specs."""
    at = f"{where}: parameter {key!r}"
    if not isinstance(spec, dict) or spec.get("type") not in DISTRIBUTION_KEYS:
        got = spec.get("type") if isinstance(spec, dict) else spec
        raise ValueError(f"{at}: unknown distribution {got!r}; valid types: {sorted(DISTRIBUTION_KEYS)}")
    kind = spec["type"]
    unknown = set(spec) - DISTRIBUTION_KEYS[kind]
    if unknown:
        raise ValueError(
            f"{at}: unknown keys {sorted(unknown)} for type {kind!r}; valid: {sorted(DISTRIBUTION_KEYS[kind])}"
        )
    if kind == "categorical":
        choices = spec.get("choices")
        if not isinstance(choices, list) or not choices:
            raise ValueError(f"{at}: choices must be a non-empty list, got {choices!r}")
        return Parameter(key, kind, choices=tuple(choices))
    number = int if kind == "int" else (int, float)
    low, high = spec.get("low"), spec.get("high")
    for name, value in (("low", low), ("high", high)):
        if isinstance(value, bool) or not isinstance(value, number):
            raise ValueError(f"{at}: {name} must be {'an integer' if kind == 'int' else 'a number'}, got {value!r}")
    if low > high:
        raise ValueError(f"{at}: low > high ({low} > {high})")
    log = spec.get("log", False)
    if not isinstance(log, bool) or (log and low <= 0):
        raise ValueError(f"{at}: log must be true or false, and a log scale needs low > 0; got log={log!r}, low={low}")
    step = spec.get("step", 1)
    if isinstance(step, bool) or not isinstance(step, int) or step < 1:
        raise ValueError(f"{at}: step must be an integer >= 1, got {step!r}")
    return Parameter(key, kind, low=low, high=high, log=log, step=step)


def load_space(space: str, env: EnvConfig, agent_cfg: str | None = None, overrides: Sequence[str] = ()) -> SearchSpace:
    """Read a space and check it before any trial runs.

    The SSL part is expanded over the auxiliary losses of the base agent config (``agent_cfg`` with
    the agent part of ``overrides``), and every bound or choice of every parameter must make a
    valid config on top of the base env (``env`` with the env part of ``overrides``) and agent:
    otherwise ValueError naming the parameter and the valid choices.
    """
    data = read_yaml(resolve_space_path(space), "search space") or {}
    where = f"search space {space!r}"
    if not isinstance(data, dict) or set(data) - set(SPACE_KEYS):
        extra = sorted(set(data) - set(SPACE_KEYS)) if isinstance(data, dict) else data
        raise ValueError(f"{where}: unknown sections {extra}; valid sections: {list(SPACE_KEYS)}")
    env_changes, agent_overrides = split_overrides(list(overrides))
    env = training_env(env, agent_cfg, env_changes)
    base = load_agent_config(env.task, agent_cfg, agent_overrides)
    parameters = [parse_parameter(str(k), v, where) for k, v in (data.get("parameters") or {}).items()]
    known = _aux_fields()
    for key, spec in (data.get("ssl_parameters") or {}).items():
        if key not in known:
            raise ValueError(f"{where}: unknown ssl parameter {key!r}; valid ssl parameters: {sorted(known)}")
        for loss, config in base.ssl.enabled().items():
            if key in {f.name for f in dataclasses.fields(config)}:
                parameters.append(parse_parameter(f"ssl.{loss}.{key}", spec, where))
    if not parameters:
        ssl = (
            " and its ssl_parameters tune none of the base config's auxiliary losses"
            if data.get("ssl_parameters")
            else ""
        )
        raise ValueError(
            f"{where}: no parameter to search (its 'parameters' are empty{ssl}); a trial would train the base "
            "config unchanged: name parameters as section.key: {type: float|int|categorical, ...}"
        )
    for parameter in parameters:
        for value in parameter.extremes():
            try:
                changes, agent_changes = split_overrides(as_overrides({parameter.key: value}))
                apply_env_overrides(env, changes)
                load_agent_config(env.task, agent_cfg, [*agent_overrides, *agent_changes])
            except (ValueError, TypeError) as error:
                message = f"{where}: parameter {parameter.key!r} = {value!r} is not a valid setting: {error}"
                raise ValueError(message) from None
    return SearchSpace(name=space, parameters=tuple(parameters))


def _aux_fields() -> set[str]:
    """Every field of every auxiliary loss's config (the keys ``ssl_parameters`` may name)."""
    every = from_dict(AgentConfig, {"ssl": {f.name: {} for f in dataclasses.fields(SSLConfig)}})
    return {f.name for config in every.ssl.enabled().values() for f in dataclasses.fields(config)}

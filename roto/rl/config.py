"""Agent configuration: frozen dataclasses built from plain mappings with strict keys.

A config mirrors ``AgentConfig``: sections ``network``, ``ppo``, ``ssl`` and ``run``. An unknown
key is an error naming its dotted path and the valid keys; a missing key keeps its default.
Reading them from files (``extends:``, overrides, ``training_aids``): ``roto.rl.config_files``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import types
import typing
from dataclasses import dataclass, field
from typing import Any

from roto.rl.ssl.configs import SSLConfig, check_groups


@dataclass(frozen=True, kw_only=True)
class NetworkConfig:
    """Encoder, heads and the observation groups each network reads (docs/spec.md §7)."""

    encoder: tuple[int, ...] = (512, 256)
    """Hidden sizes of the encoder (Linear -> LayerNorm -> ELU each)."""
    policy_head: tuple[int, ...] = (128, 64)
    """Hidden sizes of the policy head on the encoder's latent (ELU), then a linear layer to the action means."""
    value_head: tuple[int, ...] = (128, 64)
    """Hidden sizes of the value head (ELU), then a linear layer to the value."""
    init_log_std: float = 0.0
    """Initial log standard deviation of the Gaussian policy (a state-independent parameter per action)."""
    max_log_std: float = 2.0
    """Upper bound of the policy's log standard deviation (roto's clamp: 2, a std of 7.4 in action
    units of ±1). A lower bound keeps a small batch's sampled actions near the mean action
    evaluation uses (0: a std of at most 1)."""
    project_log_std: bool = False
    """After each optimiser step, put the log-std parameter back inside [-20, max_log_std], so a
    std at its bound keeps its gradient and can shrink again. False is roto's clamp in the forward
    pass only: a parameter the entropy bonus pushes past the bound gets no gradient from then on,
    and the std stays at the bound for the rest of the run."""
    obs_normalization: bool = True
    """Standardise each network's input with running statistics kept in the model (clip ±5)."""
    start_at_hold: bool = False
    """Start the policy's mean action at the hand's hold pose (``RotoEnv.hold_action``, the joint
    targets of its default pose): the action layer's weights scaled by 0.01 (``HOLD_START_GAIN``) and its
    bias set to the hold action, so every seed's first rollouts act near the hold pose, whatever its
    random init. False: PyTorch's default init, a mean action of about ±0.4 per joint away from it."""
    actor: tuple[str, ...] | None = None
    """Groups the actor (and its encoder, which the auxiliary losses train) reads; None: the obs
    mode's groups. Always a subset of the obs mode's groups."""
    critic: tuple[str, ...] | None = None
    """Groups the critic reads; None: the actor's, through the shared encoder. Other groups give the
    critic an encoder of its own (same sizes), e.g. [tactile, proprio, privileged] for a privileged critic."""


@dataclass(frozen=True, kw_only=True)
class PPOConfig:
    """PPO hyperparameters (docs/spec.md §7; defaults are roto's Bounce values)."""

    rollouts: int = 16
    """Steps each env collects per update: an update learns from rollouts x num_envs transitions."""
    epochs: int = 17
    """Passes over the collected transitions per update."""
    minibatches: int = 8
    """Minibatches per epoch (each an Adam step on rollouts x num_envs / minibatches transitions)."""
    gamma: float = 0.99
    """Discount factor."""
    lam: float = 0.951
    """GAE lambda."""
    lr: float = 2.59e-4
    """Adam learning rate (the starting rate when ``kl_adaptive``)."""
    ratio_clip: float = 0.285
    """PPO's clip of the probability ratio, 1 ± this."""
    value_clip: float = 0.105
    """Clip of the value prediction's change from the rollout's value, ± this (in normalised units)."""
    value_coef: float = 0.999
    """Weight of the value loss in the total loss."""
    entropy_coef: float = 0.0161
    """Weight of the entropy bonus (subtracted from the loss)."""
    max_grad_norm: float = 1.0
    """Gradients are clipped to this global norm before each Adam step."""
    kl_adaptive: bool = False
    """Adapt the learning rate after each epoch (from its mean KL) to keep the policy's change near ``kl_target``."""
    kl_target: float = 0.008
    """KL between the old and new policy the adaptive rate aims at."""
    kl_factor: float = 1.5
    """The adaptive rate is divided by this when the KL exceeds twice the target, multiplied when below half."""
    lr_min: float = 1e-6
    """Lowest learning rate the adaptive rate may reach."""
    lr_max: float = 1e-2
    """Highest learning rate the adaptive rate may reach."""
    value_normalization: bool = True
    """Learn values in units of the returns' running standard deviation."""
    bootstrap_timeouts: bool = False
    """At a time-out, bootstrap the return with the critic's value of the last state (roto: no)."""
    cuda_graph: bool = False
    """Replay each minibatch step from a CUDA graph (roto/rl/graphed_step.py): the same update with
    far fewer kernel launches. CUDA devices only, without auxiliary losses."""
    cuda_graph_rollout: bool = False
    """Replay the rollout's policy pass (observation normalisation, actor and critic, the action
    drawn from noise drawn just before it, its log-probability) from a CUDA graph
    (roto/rl/graphed_call.py): the same actions, one launch per env step. CUDA devices only."""
    fused_adam: bool = False
    """Step Adam with PyTorch's fused implementation (a few kernels for all parameters instead of
    several per parameter): the same update up to rounding, fewer launches on a GPU."""
    tf32_update: bool = False
    """Let the update's matrix products on a CUDA device use TF32 (10-bit mantissa inputs, FP32
    accumulation; torch.backends.cuda.matmul.allow_tf32) for its duration. No effect on a CPU."""
    compile_update: bool = False
    """Compile the update's forward pass and loss terms with torch.compile (TorchInductor fuses their
    element-wise kernels; the backward pass is compiled with them): the same losses up to rounding,
    fewer and larger kernels. With ``cuda_graph`` the compiled kernels are recorded into the graph.
    The first update compiles (tens of seconds; a C compiler, and Triton on a GPU)."""
    bf16_update: bool = False
    """Run PPO's forward and backward passes in the update under bfloat16 autocast (matrix products
    with 7-bit mantissa inputs and outputs, FP32 accumulation), the rollout's actions rescored with
    that forward so that every ratio starts at 1; weights, Adam's state, the action distribution,
    the losses and auxiliary losses' own passes stay FP32, and rollouts are untouched. About 2x
    faster updates on a CPU with AMX (recent Intel Xeons), slower on CPUs without bfloat16
    instructions (docs/training.md). Not with ``cuda_graph``."""


@dataclass(frozen=True, kw_only=True)
class RunConfig:
    """Evaluation, logging and checkpoint cadence of a training run."""

    num_eval_envs: int = 16
    """Evaluation envs (one episode each per evaluation) when the envs simulate on the CPU."""
    num_eval_envs_gpu: int = 100
    """Evaluation envs when they simulate on a CUDA device (the paper's 100)."""
    eval_every: int = 25
    """Evaluate the current weights every this many updates (and after the last one)."""
    checkpoint_every: int = 50
    """Write ``latest.pt`` (and a numbered copy ``agent_<update>.pt``) every this many updates."""
    keep_checkpoints: int = 2
    """Numbered copies kept: the newest this many (0: none; ``latest.pt`` and ``best.pt`` always stay)."""


@dataclass(frozen=True, kw_only=True)
class AgentConfig:
    """Everything that defines the learner. The defaults are roto's Bounce agent (docs/spec.md §7):
    the one place its numbers live; ``roto/configs/bounce.yaml`` names them, every other packaged
    config is a diff."""

    network: NetworkConfig = field(default_factory=NetworkConfig)
    ppo: PPOConfig = field(default_factory=PPOConfig)
    ssl: SSLConfig = field(default_factory=SSLConfig)
    run: RunConfig = field(default_factory=RunConfig)

    def validate(self) -> AgentConfig:
        """Raise ValueError on values no run can use; return self."""
        p = self.ppo
        positive = {"ppo.rollouts": p.rollouts, "ppo.epochs": p.epochs, "ppo.minibatches": p.minibatches}
        positive["run.num_eval_envs"] = self.run.num_eval_envs
        positive["run.num_eval_envs_gpu"] = self.run.num_eval_envs_gpu
        positive["run.eval_every"] = self.run.eval_every
        positive["run.checkpoint_every"] = self.run.checkpoint_every
        for name, value in positive.items():
            if value < 1:
                raise ValueError(f"{name} must be >= 1, got {value}")
        if self.run.keep_checkpoints < 0:
            raise ValueError(f"run.keep_checkpoints must be >= 0, got {self.run.keep_checkpoints}")
        if not (0.0 < p.gamma <= 1.0 and 0.0 <= p.lam <= 1.0):
            raise ValueError(f"ppo.gamma must be in (0, 1] and ppo.lam in [0, 1], got {p.gamma}, {p.lam}")
        for section in ("network", "ppo"):
            for name, value in dataclasses.asdict(getattr(self, section)).items():
                if isinstance(value, float) and not math.isfinite(value):
                    raise ValueError(f"{section}.{name} must be a finite number, got {value}")
        for name in ("encoder", "policy_head", "value_head"):
            widths = getattr(self.network, name)
            if any(width < 1 for width in widths):
                raise ValueError(f"network.{name} must list layer widths >= 1, got {list(widths)}")
        above_zero = {"lr": p.lr, "max_grad_norm": p.max_grad_norm, "kl_target": p.kl_target, "lr_min": p.lr_min}
        for name, value in above_zero.items():
            if value <= 0.0:
                raise ValueError(f"ppo.{name} must be > 0, got {value}")
        at_least_zero = {"ratio_clip": p.ratio_clip, "value_clip": p.value_clip, "value_coef": p.value_coef}
        for name, value in at_least_zero.items():  # 0: the bound of roto's released search space
            if value < 0.0:
                raise ValueError(f"ppo.{name} must be >= 0, got {value}")
        if p.kl_factor <= 1.0:
            raise ValueError(f"ppo.kl_factor must be > 1 (the adaptive rate's step), got {p.kl_factor}")
        if p.lr_min > p.lr_max:
            raise ValueError(f"ppo.lr_min must be <= ppo.lr_max, got {p.lr_min} > {p.lr_max}")
        for name in ("actor", "critic"):
            groups = getattr(self.network, name)
            if groups is not None:
                check_groups(groups, f"network.{name}")
        self.ssl.check()
        return self


def _coerce(value: Any, annotation: Any, path: str) -> Any:
    origin = typing.get_origin(annotation)
    if origin is types.UnionType:  # X | None
        (inner,) = [a for a in typing.get_args(annotation) if a is not type(None)]
        return None if value is None else _coerce(value, inner, path)
    if dataclasses.is_dataclass(annotation):
        return from_dict(annotation, value, path)
    if origin is tuple:
        item = typing.get_args(annotation)[0]
        kind = {int: "integers", str: "group names"}[item]
        if not isinstance(value, list | tuple) or not all(
            isinstance(v, item) and not isinstance(v, bool) for v in value
        ):
            raise ValueError(f"{path} must be a list of {kind}, got {value!r}")
        return tuple(value)
    if annotation is bool:
        if not isinstance(value, bool):
            raise ValueError(f"{path} must be true or false, got {value!r}")
        return value
    if annotation is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ValueError(f"{path} must be an integer, got {value!r}")
        return value
    if annotation is float:
        if isinstance(value, str):  # YAML 1.1 reads 1e-3 (no dot) as a string
            with contextlib.suppress(ValueError):
                value = float(value)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(f"{path} must be a number, got {value!r}")
        return float(value)
    raise TypeError(f"{path}: unsupported annotation {annotation!r}")  # pragma: no cover


def from_dict(cls: type, data: Any, path: str = "") -> Any:
    """Build dataclass ``cls`` from a mapping; unknown keys raise ValueError with their dotted path."""
    where = path or "the agent config"
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ValueError(f"{where} must be a mapping, got {data!r}")
    hints = typing.get_type_hints(cls)
    fields = {f.name for f in dataclasses.fields(cls)}
    for key in data:
        if key not in fields:
            dotted = f"{path}.{key}" if path else str(key)
            raise ValueError(f"unknown config key {dotted!r}; valid keys here: {sorted(fields)}")
    values = {k: _coerce(v, hints[k], f"{path}.{k}" if path else k) for k, v in data.items()}
    return cls(**values)


def to_dict(config: Any) -> dict[str, Any]:
    """Plain nested dict (tuples as lists, switched-off losses left out), ready for YAML."""

    def plain(value: Any) -> Any:
        if isinstance(value, tuple):
            return list(value)
        if isinstance(value, dict):
            return {k: plain(v) for k, v in value.items()}
        return value

    data = plain(dataclasses.asdict(config))
    if "ssl" in data:
        data["ssl"] = {name: loss for name, loss in data["ssl"].items() if loss is not None}
    return data


__all__ = [
    "AgentConfig",
    "NetworkConfig",
    "PPOConfig",
    "RunConfig",
    "SSLConfig",
    "from_dict",
    "to_dict",
]

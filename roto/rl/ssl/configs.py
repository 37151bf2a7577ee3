"""Configs of the self-supervised auxiliary losses (docs/spec.md §7, §7a): frozen, strict keys.

Each loss is enabled by naming it under the agent config's ``ssl`` section, e.g.::

    ssl:
      forward_dynamics: {weight: 0.0021, lr: 1.5e-5, seq_length: 8}
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from roto.envs.observations import OBS_GROUPS


@dataclass(frozen=True, kw_only=True)
class AuxLossConfig:
    """What every auxiliary loss has: its weight in the total loss, its own Adam, its epochs."""

    weight: float = 0.01
    """w: the loss enters the update as w · loss, in the same backward pass as PPO's terms."""
    lr: float = 1e-4
    """Learning rate of the loss's own Adam (its heads and the actor's encoder)."""
    epoch_ratio: float = 1.0
    """rho: the loss is used in the first max(1, floor(epochs · rho)) epochs of each update."""

    def check(self, path: str) -> None:
        """Raise ValueError naming ``path`` on values no run can use."""
        if self.weight < 0.0 or self.lr <= 0.0:
            raise ValueError(f"{path}: weight must be >= 0 and lr > 0, got {self.weight}, {self.lr}")
        if not 0.0 < self.epoch_ratio <= 1.0:
            raise ValueError(f"{path}.epoch_ratio must be in (0, 1], got {self.epoch_ratio}")


@dataclass(frozen=True, kw_only=True)
class ReconstructionConfig(AuxLossConfig):
    """Decode the stacked target groups from the encoder's latent (tactile: weighted BCE, others: MSE)."""

    decoder: tuple[int, ...] = (512, 1024)
    """Hidden sizes of the decoder after the latent (Linear -> LayerNorm -> ELU each), then a linear output."""
    targets: tuple[str, ...] = ("tactile",)
    """Observation groups to reconstruct (stacked frames, as the env returns them)."""

    def check(self, path: str) -> None:
        """As ``AuxLossConfig.check``, plus known, non-empty targets."""
        super().check(path)
        check_groups(self.targets, f"{path}.targets")


@dataclass(frozen=True, kw_only=True)
class FullReconstructionConfig(ReconstructionConfig):
    """Reconstruction of proprioception (MSE) and touch (weighted BCE)."""

    targets: tuple[str, ...] = ("proprio", "tactile")


@dataclass(frozen=True, kw_only=True)
class ForwardDynamicsConfig(AuxLossConfig):
    """Predict the EMA target encoder's next latent from the online latent and the action, on every
    sequence of the current rollout."""

    seq_length: int = 8
    """L: observations per sequence (L - 1 one-step predictions from the true latents; no episode
    end inside the sequence)."""
    tau: float = 0.01
    """EMA rate of the target encoder, applied after every optimiser step."""
    latent_model: tuple[int, ...] = (512, 256)
    """Hidden sizes of the residual latent model g(z, a) = z + MLP([z, a]) (ELU); output = latent width."""
    projector: tuple[int, ...] = (256,)
    """Hidden sizes of the projector on the prediction (ELU), then a linear layer to the latent width."""
    max_sequences: int = 0
    """Sequences trained on per update, drawn at random without replacement from those available;
    0: all of them (roto). Overlapping windows encode each observation up to L times, so a cap
    of about rollouts x num_envs / (L - 1) keeps the cost near one pass over the rollout."""

    def check(self, path: str) -> None:
        """As ``AuxLossConfig.check``, plus L >= 1 and tau in (0, 1]."""
        super().check(path)
        if self.seq_length < 2:
            raise ValueError(f"{path}.seq_length must be >= 2 (observations per sequence), got {self.seq_length}")
        if not 0.0 < self.tau <= 1.0:
            raise ValueError(f"{path}.tau must be in (0, 1], got {self.tau}")
        if self.max_sequences < 0:
            raise ValueError(f"{path}.max_sequences must be >= 0 (0: all), got {self.max_sequences}")


@dataclass(frozen=True, kw_only=True)
class ForwardDynamicsMemoryConfig(ForwardDynamicsConfig):
    """Forward dynamics trained on its own FIFO memory of sequences (which may span two rollouts),
    not on the current rollout's."""

    seq_length: int = 2
    capacity: int = 0
    """Sequences the memory holds; 0 means rollouts x num_envs (roto's size)."""

    def check(self, path: str) -> None:
        """As ``ForwardDynamicsConfig.check``, plus capacity >= 0."""
        super().check(path)
        if self.capacity < 0:
            raise ValueError(f"{path}.capacity must be >= 0 (0: rollouts x num_envs), got {self.capacity}")


@dataclass(frozen=True, kw_only=True)
class SSLConfig:
    """The auxiliary losses of a run: each one named here is on (any number of them; none by default)."""

    tactile_reconstruction: ReconstructionConfig | None = None
    full_reconstruction: FullReconstructionConfig | None = None
    forward_dynamics: ForwardDynamicsConfig | None = None
    forward_dynamics_memory: ForwardDynamicsMemoryConfig | None = None

    def enabled(self) -> dict[str, AuxLossConfig]:
        """{loss name: its config} of the losses that are on, in declaration order."""
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None}

    def check(self) -> None:
        """Check every enabled loss's values."""
        for name, config in self.enabled().items():
            config.check(f"ssl.{name}")


def check_groups(groups: tuple[str, ...], path: str) -> None:
    """Raise ValueError unless ``groups`` is a non-empty tuple of distinct known observation groups."""
    if not groups:
        raise ValueError(f"{path} must name at least one observation group; valid groups: {list(OBS_GROUPS)}")
    for group in groups:
        if group not in OBS_GROUPS:
            raise ValueError(f"{path}: unknown observation group {group!r}; valid groups: {list(OBS_GROUPS)}")
    if len(set(groups)) != len(groups):
        raise ValueError(f"{path} names a group twice: {list(groups)}")

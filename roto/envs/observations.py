"""Per-frame observation groups (docs/spec.md §4) and the frame stack, as batched torch."""

from __future__ import annotations

import torch

OBS_GROUPS: tuple[str, ...] = ("tactile", "proprio", "privileged", "task")
"""Every observation group an env can return, in the order the env concatenates them. ``task`` (the
task's own state: Baoding's current targets and latches, Bounce's counter state, and the share of
the episode left) is in no observation mode: it is for critics and other learners that read it
beside the policy (``EnvConfig.extra_groups``)."""

OBS_MODES: dict[str, tuple[str, ...]] = {
    "blind": ("tactile", "proprio"),
    "state": ("tactile", "proprio", "privileged"),
    "proprio": ("proprio",),
}
"""Observation mode -> groups, in the order they are concatenated."""

TOUCH_MODES: tuple[str, ...] = ("binary", "force", "taxels")
"""What the tactile group holds: ``binary`` a touch bit per tactile link (the benchmark's signal),
``force`` the magnitude of each link's net contact force on a log scale (``touch_force``),
``taxels`` the links' bits followed by one bit per taxel of the fingertip pads and the palm."""

FORCE_SCALE = 0.1
"""F0 (N) of the ``force`` touch signal log(1 + |F| / F0): a 30 g ball resting on a hand (0.29 N)
reads about 1.4, a 10 N impact about 4.6."""

JOINT_VELOCITY_SCALE = 1.0 / 3.0
"""Joint velocities (rad/s) are multiplied by this in the proprio group (roto divides by 3)."""


def tactile_bits(contact_force: torch.Tensor, threshold: float) -> torch.Tensor:
    """Binary touch per link: 1 where the link's strongest contact pushes harder than ``threshold`` N.

    Args:
        contact_force: (B, n_links) normal force of each link's strongest contact (0 if none).

    Returns:
        (B, n_links) float32 in {0, 1}.
    """
    return (contact_force > threshold).to(torch.float32)


def touch_force(net_force: torch.Tensor, scale: float = FORCE_SCALE) -> torch.Tensor:
    """Force touch per link: log(1 + |F| / F0) of the link's net contact force F.

    Args:
        net_force: (B, n_links, 3) net force of all the link's contacts, N (zero without contact).

    Returns:
        (B, n_links) float32, 0 without contact.
    """
    return torch.log1p(torch.linalg.vector_norm(net_force, dim=-1) / scale).to(torch.float32)


def tactile_frame(
    touch: str, link_force: torch.Tensor, taxel_force: torch.Tensor | None, threshold: float
) -> torch.Tensor:
    """The tactile group of one frame in touch mode ``touch`` (``TOUCH_MODES``).

    Args:
        link_force: per tactile link, (B, n_links) its strongest contact's normal force, or with
            ``force`` touch (B, n_links, 3) its net contact force.
        taxel_force: (B, n_taxels) each taxel's normal force (``taxels`` touch only).
        threshold: force (N) above which a link or a taxel counts as touched.

    Returns:
        (B, n_links) float32, or (B, n_links + n_taxels) with ``taxels``; NaN and inf read as 0.
    """
    if touch == "force":
        return touch_force(link_force).nan_to_num_(nan=0.0, posinf=0.0, neginf=0.0)
    bits = tactile_bits(link_force, threshold)
    if touch == "taxels":
        return torch.cat([bits, tactile_bits(taxel_force, threshold)], dim=-1)
    return bits


def proprio_parts(qpos, qvel, lo, hi, target, actuated_qpos, velocity_scale: float = JOINT_VELOCITY_SCALE):
    """The computed parts of proprioception, with arithmetic operators only, so that numpy arrays
    and torch tensors both work: normalised positions, scaled velocities, command error.

    Args:
        qpos: (B, n_obs) observed joint positions; qvel: (B, n_obs) their velocities.
        lo, hi: (n_obs,) their limits.
        target: (B, n_act) joint targets; actuated_qpos: (B, n_act) actuated joint positions.

    Returns:
        ((B, n_obs) positions in [-1, 1] within the limits, (B, n_obs) velocities, (B, n_act) errors).
    """
    return (2.0 * qpos - hi - lo) / (hi - lo), qvel * velocity_scale, target - actuated_qpos


def proprio_frame(
    qpos: torch.Tensor,
    qvel: torch.Tensor,
    lo: torch.Tensor,
    hi: torch.Tensor,
    target: torch.Tensor,
    actuated_qpos: torch.Tensor,
    last_action: torch.Tensor,
    velocity_scale: float = JOINT_VELOCITY_SCALE,
) -> torch.Tensor:
    """Proprioception: normalised positions, scaled velocities, command error, last action
    (``proprio_parts`` and the raw policy action ``last_action`` (B, n_act) of this step).

    Returns:
        (B, 2·n_obs + 2·n_act) float32.
    """
    pos, vel, error = proprio_parts(qpos, qvel, lo, hi, target, actuated_qpos, velocity_scale)
    return torch.cat([pos, vel, error, last_action.to(pos.dtype)], dim=-1).to(torch.float32)


def privileged_frame(ball_pos: torch.Tensor, ball_vel: torch.Tensor) -> torch.Tensor:
    """Object state: each ball's position (task frame, m) and linear velocity (m/s).

    Args:
        ball_pos, ball_vel: (B, n_ball, 3).

    Returns:
        (B, 6·n_ball) float32, per ball (x, y, z, vx, vy, vz).
    """
    return torch.cat([ball_pos, ball_vel], dim=-1).flatten(1).to(torch.float32)


def ball_positions(privileged: torch.Tensor, n_ball: int) -> torch.Tensor:
    """The balls' centres in the newest frame of a stacked ``privileged`` group (``privileged_frame``'s layout).

    Args:
        privileged: (B, k·6·n_ball), k frames oldest to newest.

    Returns:
        (B, n_ball, 3) positions (task frame, m).
    """
    newest = privileged[:, -6 * n_ball :]
    return newest.unflatten(1, (n_ball, 6))[..., :3]


def task_frame(task_observation: torch.Tensor, length: torch.Tensor, episode_steps: int) -> torch.Tensor:
    """The ``task`` group: the task's state features (``Task.observation``), then the share of the
    episode left.

    Args:
        task_observation: (B, k) the task's features.
        length: (B,) control steps taken so far this episode.
        episode_steps: control steps per episode.

    Returns:
        (B, k + 1) float32.
    """
    left = 1.0 - length.to(torch.float64) / episode_steps
    return torch.cat([task_observation.to(torch.float64), left[:, None]], dim=-1).to(torch.float32)


class FrameStack:
    """The last k frames of each group, oldest -> newest, held flat as (B, k·dim) per group."""

    def __init__(self, k: int) -> None:
        if k < 1:
            raise ValueError(f"frame stack k must be >= 1, got {k}")
        self.k = k
        self._frames: dict[str, torch.Tensor] = {}

    @property
    def frames(self) -> dict[str, torch.Tensor]:
        """The stacked frames themselves, (B, k·dim) per group: the tensors the stack holds now (a
        step replaces them; ``roto.envs.single_world`` writes its newest frame into them in place)."""
        return self._frames

    def reset(self, frame: dict[str, torch.Tensor], env_ids: torch.Tensor | None = None) -> None:
        """Fill the stack of ``env_ids`` (all if None) with k copies of ``frame`` ((n, dim) per group)."""
        for name, value in frame.items():
            copies = value.repeat(1, self.k)
            if env_ids is None:
                self._frames[name] = copies
            else:
                self._frames[name][env_ids] = copies

    def reset_where(self, frame: dict[str, torch.Tensor], mask: torch.Tensor) -> None:
        """Fill the stacks of the worlds where ``mask`` (B,) bool is True with k copies of their
        rows of ``frame`` ((B, dim) per group); no host read."""
        rows = mask[:, None]
        for name, value in frame.items():
            self._frames[name] = torch.where(rows, value.repeat(1, self.k), self._frames[name])

    def push(self, frame: dict[str, torch.Tensor]) -> None:
        """Append one frame ((B, dim) per group), dropping the oldest."""
        for name, value in frame.items():
            self._frames[name] = torch.cat([self._frames[name][:, value.shape[-1] :], value], dim=1)

    def state_dict(self) -> dict[str, torch.Tensor]:
        """Copies of the stacked frames, (B, k, dim) per group."""
        return {name: frames.unflatten(1, (self.k, -1)).clone() for name, frames in self._frames.items()}

    def load_state_dict(self, state: dict[str, torch.Tensor]) -> None:
        """Restore what ``state_dict`` returned."""
        self._frames = {name: frames.flatten(1).clone() for name, frames in state.items()}

    def observation(self) -> dict[str, torch.Tensor]:
        """(B, k·dim) per group; fresh tensors each step, never views of internal buffers."""
        return {name: frames.clone() for name, frames in self._frames.items()}

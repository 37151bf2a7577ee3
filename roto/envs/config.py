"""Environment configuration (frozen; validated on construction)."""

from __future__ import annotations

from dataclasses import dataclass

from roto.envs.observations import OBS_MODES

BACKENDS = ("cpu",)
"""Physics backends available in this build."""


@dataclass(frozen=True, kw_only=True)
class EnvConfig:
    """Everything that defines a batched roto environment.

    Attributes:
        task: task name (``bounce``, ``baoding``).
        robot: robot name (``shadow``).
        num_envs: number of parallel worlds B (>= 1).
        obs_mode: ``blind`` (proprio + tactile), ``state`` (+ privileged), ``proprio`` (no touch).
        backend: physics backend (``cpu``: MuJoCo C threads).
        device: torch device of all tensors the env returns.
        seed: seed of the reset noise.
        threads: C threads stepping the worlds (CPU backend).
        frame_stack: frames k stacked per observation group.
        substeps: physics steps per control step (1/240 s each).
        episode_steps: control steps per episode (10 s at 60 Hz).
        action_smoothing: alpha of the exponential smoothing of joint targets (1 = none).
        tactile_threshold: normal force (N) above which a link counts as touched.
        reset_joint_noise: half-width (rad) of the uniform noise added to the default pose at reset.
    """

    task: str
    robot: str = "shadow"
    num_envs: int = 1
    obs_mode: str = "blind"
    backend: str = "cpu"
    device: str = "cpu"
    seed: int = 0
    threads: int = 1
    frame_stack: int = 4
    substeps: int = 4
    episode_steps: int = 600
    action_smoothing: float = 1.0
    tactile_threshold: float = 0.01
    reset_joint_noise: float = 0.2

    def __post_init__(self) -> None:
        """Reject impossible values with a message naming the value and the valid choices."""
        from roto.robots import get_robot
        from roto.tasks import get_task

        get_task(self.task)
        get_robot(self.robot)
        if self.obs_mode not in OBS_MODES:
            raise ValueError(f"unknown obs_mode {self.obs_mode!r}; valid obs modes: {list(OBS_MODES)}")
        if self.backend not in BACKENDS:
            raise ValueError(f"unknown backend {self.backend!r}; valid backends: {list(BACKENDS)}")
        if isinstance(self.num_envs, bool) or not isinstance(self.num_envs, int) or self.num_envs < 1:
            raise ValueError(f"num_envs must be an integer >= 1, got {self.num_envs!r}")
        if isinstance(self.threads, bool) or not isinstance(self.threads, int) or self.threads < 1:
            raise ValueError(f"threads must be an integer >= 1, got {self.threads!r}")
        if self.frame_stack < 1:
            raise ValueError(f"frame_stack must be >= 1, got {self.frame_stack!r}")
        if self.substeps < 1 or self.episode_steps < 1:
            raise ValueError(f"substeps and episode_steps must be >= 1, got {self.substeps}, {self.episode_steps}")
        if not 0.0 < self.action_smoothing <= 1.0:
            raise ValueError(f"action_smoothing must be in (0, 1], got {self.action_smoothing!r}")
        if self.device != "cpu" and not str(self.device).startswith("cpu"):
            raise ValueError(f"device {self.device!r} is not available with backend {self.backend!r}; valid: ['cpu']")

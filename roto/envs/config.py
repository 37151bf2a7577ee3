"""Environment configuration (frozen; validated on construction)."""

from __future__ import annotations

import dataclasses
import importlib.util
from dataclasses import dataclass, field
from math import inf

from roto.envs.aids.settings import AidsConfig, parse_aids
from roto.envs.observations import OBS_GROUPS, OBS_MODES, TOUCH_MODES
from roto.sim.backend import BACKENDS
from roto.value_checks import check_count, check_number

MAX_SEED = 2**63 - 1
"""The largest seed the reset noise's generator takes (a non-negative 64-bit integer, as Gymnasium's)."""


@dataclass(frozen=True, kw_only=True)
class EnvConfig:
    """Everything that defines a batched roto environment.

    Attributes:
        task: task name (``bounce``, ``baoding``).
        robot: robot name (``shadow``).
        num_envs: number of parallel worlds B (>= 1).
        obs_mode: ``blind`` (proprio + tactile), ``state`` (+ privileged), ``proprio`` (no touch).
        extra_groups: observation groups returned besides the obs mode's, for a learner that reads
            them outside the policy (a privileged critic, an auxiliary target); the policy's input
            stays the obs mode's groups.
        backend: physics backend (``cpu``: MuJoCo C threads; ``warp``: MuJoCo Warp, see docs/backends.md).
        device: torch device of all tensors the env returns, and where ``warp`` simulates
            (``cpu`` or ``cuda[:k]``; the ``cpu`` backend needs ``cpu``).
        seed: seed of the reset noise (an integer in [0, 2**63 - 1], as Gymnasium's seeds).
        threads: C threads stepping the worlds (CPU backend).
        frame_stack: frames k stacked per observation group.
        substeps: physics steps per control step (1/240 s each).
        episode_steps: control steps per episode (10 s at 60 Hz).
        action_smoothing: alpha of the exponential smoothing of joint targets (1 = none).
        touch: what the tactile group holds: ``binary`` (a touch bit per link, the benchmark's
            signal), ``force`` (log(1 + |F| / 0.1 N) of each link's net contact force) or
            ``taxels`` (the links' bits, then a bit per taxel of the fingertip pads and the palm).
        tactile_threshold: normal force (N, >= 0) above which a link or a taxel counts as touched.
        reset_joint_noise: half-width (rad, >= 0) of the uniform noise added to the default pose at reset.
        nconmax: contacts per world the ``warp`` backend allocates (None: roto's measured figure for
            this robot and task, ``PairRecord.warp_capacity``).
        njmax: constraint rows per world for ``warp`` (None: as for ``nconmax``).
        aids: the training aids of the training envs (``roto.envs.aids.settings``: replayed
            starts, a tolerance curriculum, round swaps, turn shaping; none by default). A plain
            mapping ({aid: {setting: value}}, as YAML holds it) is read into ``AidsConfig``.
            Evaluation envs carry none (``without_training_aids``).
    """

    task: str
    robot: str = "shadow"
    num_envs: int = 1
    obs_mode: str = "blind"
    extra_groups: tuple[str, ...] = ()
    backend: str = "cpu"
    device: str = "cpu"
    seed: int = 0
    threads: int = 1
    frame_stack: int = 4
    substeps: int = 4
    episode_steps: int = 600
    action_smoothing: float = 1.0
    touch: str = "binary"
    tactile_threshold: float = 0.01
    reset_joint_noise: float = 0.2
    nconmax: int | None = None
    njmax: int | None = None
    aids: AidsConfig = field(default_factory=AidsConfig)

    def __post_init__(self) -> None:
        """Reject impossible values with a message naming the value and the valid choices."""
        from roto.robots import get_robot
        from roto.tasks import get_task

        get_task(self.task)
        get_robot(self.robot)
        if self.obs_mode not in OBS_MODES:
            raise ValueError(f"unknown obs_mode {self.obs_mode!r}; valid obs modes: {list(OBS_MODES)}")
        if self.touch not in TOUCH_MODES:
            raise ValueError(f"unknown touch {self.touch!r}; valid touch modes: {list(TOUCH_MODES)}")
        object.__setattr__(self, "extra_groups", tuple(self.extra_groups))  # a list read back from YAML
        for group in self.extra_groups:
            if group not in OBS_GROUPS:
                raise ValueError(f"unknown extra observation group {group!r}; valid groups: {list(OBS_GROUPS)}")
        if self.backend not in BACKENDS:
            raise ValueError(f"unknown backend {self.backend!r}; valid backends: {list(BACKENDS)}")
        for name in ("num_envs", "threads", "frame_stack", "substeps", "episode_steps"):
            check_count(name, getattr(self, name), 1)
        check_count("seed", self.seed, 0, MAX_SEED)
        smoothing = self.action_smoothing
        if isinstance(smoothing, bool) or not isinstance(smoothing, int | float) or not 0.0 < smoothing <= 1.0:
            raise ValueError(f"action_smoothing must be a number in (0, 1], got {smoothing!r}")
        check_number("tactile_threshold", self.tactile_threshold, 0.0, inf, "a force (N)")
        check_number("reset_joint_noise", self.reset_joint_noise, 0.0, inf, "a half-width (rad)")
        for name in ("nconmax", "njmax"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 1):
                raise ValueError(f"{name} must be an integer >= 1 or None, got {value!r}")
        object.__setattr__(self, "aids", parse_aids(self.aids))  # a mapping read back from YAML
        self.aids.check(get_task(self.task))
        self._check_device()

    def without_training_aids(self) -> EnvConfig:
        """This config as the benchmark defines the task: every training aid at its default (off)."""
        return dataclasses.replace(self, aids=AidsConfig())

    def _check_device(self) -> None:
        device = str(self.device)
        if self.backend == "cpu":
            if device != "cpu":
                raise ValueError(
                    f"device {device!r} is not available with backend 'cpu'; valid: ['cpu'] "
                    "(backend='warp' simulates on a CUDA device)"
                )
            return
        if device != "cpu" and not (device == "cuda" or device.startswith("cuda:")):
            raise ValueError(f"device {device!r} is not valid with backend 'warp'; valid: ['cpu', 'cuda', 'cuda:<k>']")

    def check_available(self) -> None:
        """Raise ValueError unless this machine can build these envs: MuJoCo Warp installed for
        backend 'warp', a CUDA GPU for a CUDA device. Checked when envs are made, not when a config
        is read, so a GPU-trained run's config (a checkpoint's) loads anywhere for CPU evaluation."""
        if self.backend == "cpu":
            return
        device = str(self.device)
        if importlib.util.find_spec("mujoco_warp") is None:
            raise ValueError("backend 'warp' needs MuJoCo Warp, which is not installed: pip install -e '.[gpu]'")
        if device.startswith("cuda"):
            import torch

            if not torch.cuda.is_available():
                raise ValueError(
                    f"device {device!r} was asked for, but this machine has no CUDA GPU that torch can use; "
                    "use device='cpu' (Warp's CPU device, slow) or backend='cpu'"
                )

"""Environment configuration (frozen; validated on construction)."""

from __future__ import annotations

import dataclasses
import importlib.util
from dataclasses import dataclass

from roto.envs.observations import OBS_GROUPS, OBS_MODES, TOUCH_MODES
from roto.sim.backend import BACKENDS

TRAINING_AID_FIELDS = (
    "replay_starts",
    "replay_share",
    "replay_record_lead",
    "replay_record_capacity",
    "tolerance_start",
    "tolerance_target",
    "swap_min_turn",
    "turn_reward",
)
"""The env fields that are training aids: a run's training envs may set them; evaluation and the
benchmark never do (``EnvConfig.without_training_aids``)."""


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
        seed: seed of the reset noise.
        threads: C threads stepping the worlds (CPU backend).
        frame_stack: frames k stacked per observation group.
        substeps: physics steps per control step (1/240 s each).
        episode_steps: control steps per episode (10 s at 60 Hz).
        action_smoothing: alpha of the exponential smoothing of joint targets (1 = none).
        touch: what the tactile group holds: ``binary`` (a touch bit per link, the benchmark's
            signal), ``force`` (log(1 + |F| / 0.1 N) of each link's net contact force) or
            ``taxels`` (the links' bits, then a bit per taxel of the fingertip pads and the palm).
        tactile_threshold: normal force (N) above which a link or a taxel counts as touched.
        reset_joint_noise: half-width (rad) of the uniform noise added to the default pose at reset.
        nconmax: contacts per world the ``warp`` backend allocates (None: roto's measured figure for
            this robot and task, ``roto.envs.capacity``).
        njmax: constraint rows per world for ``warp`` (None: as for ``nconmax``).
        replay_starts: a training aid: an ``.npz`` of recorded states (``roto demo --task baoding
            --preswap_out``: states just before swaps) that episodes may start from.
        replay_share: the share of episode starts drawn from ``replay_starts`` instead of the
            task's own starts (0: none). Training only: evaluation envs always start from the
            task's own starts (``without_training_aids``).
        replay_record_lead: a training aid beside ``replay_starts`` (0: off): the training envs'
            own states this many control steps before each rise of the task's headline metric
            (a Baoding swap) join the bank they replay from (``roto.envs.aids.event_recorder``).
        replay_record_capacity: the most states so recorded (the oldest replaced first).
        tolerance_start: a training aid for a task with a success radius (Baoding; 0: off): the
            radius starts this wide (m) and narrows to the task's own as the training episodes'
            headline metric rises (``roto.envs.aids.tolerance``).
        tolerance_target: the headline metric per training episode (Baoding: rotations) at which
            the radius is the task's own.
        swap_min_turn: a training aid for Baoding (0: off): a swap earns its reward only when the
            line from one ball to the other has turned at least this many turns since the last
            paid swap, the same way round as the episode's first (0.25: a quarter turn; a pair
            carried round turns half a turn a swap, one swung out and back is paid once an
            episode). Swaps still count as roto counts them (``roto.tasks.round_swaps``).
        turn_reward: a training aid for Baoding (0: off): reward per turn the magnitude of the
            pair's net turning this episode grows (given back as it shrinks: a potential-based
            shaping term, "turn"), so a pair carried round earns it and a swing out and back does
            not (``roto.tasks.round_swaps.turn_shaping``).
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
    replay_starts: str | None = None
    replay_share: float = 0.0
    replay_record_lead: int = 0
    replay_record_capacity: int = 1024
    tolerance_start: float = 0.0
    tolerance_target: float = 1.0
    swap_min_turn: float = 0.0
    turn_reward: float = 0.0

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
        for name in ("nconmax", "njmax"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 1):
                raise ValueError(f"{name} must be an integer >= 1 or None, got {value!r}")
        self._check_replay()
        self._check_tolerance()
        self._check_turn_aids()
        self._check_device()

    def without_training_aids(self) -> EnvConfig:
        """This config as the benchmark defines the task: every training aid at its default (off)."""
        defaults = {f.name: f.default for f in dataclasses.fields(EnvConfig) if f.name in TRAINING_AID_FIELDS}
        return dataclasses.replace(self, **defaults)

    def _check_replay(self) -> None:
        share = self.replay_share
        if isinstance(share, bool) or not isinstance(share, (int, float)) or not 0.0 <= share <= 1.0:
            raise ValueError(f"replay_share must be a number in [0, 1], got {share!r}")
        if share > 0.0 and self.replay_starts is None:
            raise ValueError(f"replay_share {share} needs replay_starts (an .npz of recorded states); got none")
        for name, low in (("replay_record_lead", 0), ("replay_record_capacity", 1)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
        if self.replay_record_lead > 0 and share == 0.0:
            raise ValueError(
                f"replay_record_lead {self.replay_record_lead} records states for replayed starts, but replay_share "
                "is 0 (nothing would replay them); set replay_share and replay_starts"
            )

    def _check_tolerance(self) -> None:
        from roto.tasks import get_task

        start, target = self.tolerance_start, self.tolerance_target
        for name, value in (("tolerance_start", start), ("tolerance_target", target)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0.0:
                raise ValueError(f"{name} must be a number >= 0, got {value!r}")
        if start == 0.0:
            return
        own = get_task(self.task).parameters.get("success_radius")
        if own is None:
            raise ValueError(
                f"tolerance_start applies to a task with a success radius (baoding); task {self.task!r} has none"
            )
        if start < own or target <= 0.0:
            raise ValueError(
                f"tolerance_start must be at least the task's own radius {own} m and tolerance_target > 0, "
                f"got {start}, {target}"
            )

    def _check_turn_aids(self) -> None:
        from roto.tasks import get_task

        value = self.swap_min_turn
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 0.5:
            raise ValueError(f"swap_min_turn must be a number of turns in [0, 0.5] (0: off), got {value!r}")
        if value > 0.0 and "swap_min_turn" not in get_task(self.task).parameters:
            raise ValueError(f"swap_min_turn applies to a task with swaps (baoding); task {self.task!r} has none")
        value = self.turn_reward
        if isinstance(value, bool) or not isinstance(value, int | float) or not 0.0 <= value <= 1000.0:
            raise ValueError(f"turn_reward must be a reward per turn in [0, 1000] (0: off), got {value!r}")
        if value > 0.0 and "turn_reward" not in get_task(self.task).parameters:
            raise ValueError(f"turn_reward applies to a task with a ball pair (baoding); task {self.task!r} has none")

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

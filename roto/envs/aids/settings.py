"""The env config's ``aids`` section: which training aids a run's training envs carry, with what
settings (frozen, strict keys, checked on construction). Evaluation envs carry none
(``EnvConfig.without_training_aids``).

In YAML (an env config, an agent config's ``training_aids`` section, ``roto.make(aids=...)``)::

    aids:
      replayed_starts: {bank: "{robot}_round_preswap", share: 0.5, record_lead: 10}
      tolerance: {start: 0.025, target: 2}
      round_swaps: {min_turn: 0.25}
      turn_shaping: {per_turn: 20}

and as overrides ``env.aids.tolerance.start=0.025``. An aid not named is off. Each setting's
meaning is on its class; what each aid does is in its module (``roto.envs.aids.<module>``).
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from roto.value_checks import check_count, check_number


def _needs_parameter(path: str, task: Any, parameter: str, what: str, tasks: str = "baoding") -> None:
    if parameter not in task.parameters:
        raise ValueError(f"{path} applies to a task with {what} ({tasks}); task {task.name!r} has none")


@dataclass(frozen=True, kw_only=True)
class ReplayedStartsSettings:
    """Episodes start from recorded states (``roto.envs.aids.replayed_starts``).

    Attributes:
        bank: an ``.npz`` of recorded states (``roto demo --task baoding --preswap_out``: states
            just before swaps), ``{robot}`` standing for the hand where a config names it.
        share: the share of episode starts drawn from the bank instead of the task's own.
        record_lead: 0: off; else the training envs' own states this many control steps before
            each rise of the task's headline metric (a Baoding swap) join the bank
            (``roto.envs.aids.event_recorder``).
        record_capacity: the most states so recorded (the oldest replaced first).
    """

    bank: str
    share: float = 0.25
    record_lead: int = 0
    record_capacity: int = 1024

    def check(self, path: str, task: Any) -> None:
        if not isinstance(self.bank, str) or not self.bank:
            raise ValueError(f"{path}.bank must name an .npz of recorded states, got {self.bank!r}")
        check_number(f"{path}.share", self.share, 0.0, 1.0, "a share")
        check_count(f"{path}.record_lead", self.record_lead, 0)
        check_count(f"{path}.record_capacity", self.record_capacity, 1)
        if self.record_lead > 0 and self.share == 0.0:
            raise ValueError(
                f"{path}.record_lead {self.record_lead} records states for replayed starts, but {path}.share is 0 "
                "(nothing would replay them); set a share above 0"
            )


TOLERANCE_MEASURES = ("headline", "net_turns")
"""What a tolerance curriculum's episodes may be measured by (``ToleranceSettings.by``)."""


@dataclass(frozen=True, kw_only=True)
class ToleranceSettings:
    """The task's success radius starts wide and narrows to its own as training episodes succeed
    (``roto.envs.aids.tolerance``).

    Attributes:
        start: the radius (m) while no training episode succeeds (at least the task's own).
        target: the training episodes' mean of ``by`` at which the radius is the task's own.
        by: what the episodes are measured by: ``headline``, the task's headline metric
            (Baoding: rotations, counted at the radius of the moment, so a policy that latches only
            at a wide radius can hold it wide); ``net_turns``, the size of the ball pair's net
            turning, which no radius changes (Baoding), so the radius narrows as the policy learns
            to turn the pair wherever it turns it.
        deadline: None: none; else training env steps (every world's control steps together)
            from which the radius is the task's own whatever the episodes score.
    """

    start: float
    target: float = 1.0
    by: str = "headline"
    deadline: int | None = None

    def check(self, path: str, task: Any) -> None:
        _needs_parameter(path, task, "success_radius", "a success radius")
        own = task.parameters["success_radius"]
        check_number(f"{path}.start", self.start, own, 1.0, f"a radius (m) no smaller than the task's own {own}")
        if self.by not in TOLERANCE_MEASURES:
            raise ValueError(f"{path}.by must be one of {list(TOLERANCE_MEASURES)}, got {self.by!r}")
        check_number(f"{path}.target", self.target, 1e-9, 1e6, f"a mean of {self.by} per episode")
        if self.by == "net_turns":
            _needs_parameter(f"{path}.by", task, "turn_reward", "a ball pair")
        if self.deadline is not None:
            check_count(f"{path}.deadline", self.deadline, 1)


@dataclass(frozen=True, kw_only=True)
class RoundSwapsSettings:
    """A swap is paid only after the pair turned ``min_turn`` turns the episode's way round
    (``roto.envs.aids.round_swaps``).

    Attributes:
        min_turn: the turns of the line between the balls, since the last paid swap and the same
            way round as the episode's first, that a paid swap must follow (a pair carried round
            turns half a turn a swap; one swung out and back is paid once an episode).
        first_paid: an episode's first swap is paid however little the pair turned before it (its
            way round becomes the episode's): a replayed start, a few control steps before a swap,
            keeps its swap's reward, which ``min_turn`` alone would withhold.
        after: None: from the first step; else every swap is paid until the training episodes
            reach this many rotations (the running mean over ended episodes the tolerance
            curriculum also follows), and ``min_turn`` holds from then on, even if they fall back.
    """

    min_turn: float = 0.25
    first_paid: bool = False
    after: float | None = None

    def check(self, path: str, task: Any) -> None:
        _needs_parameter(path, task, "swap_min_turn", "swaps")
        check_number(f"{path}.min_turn", self.min_turn, 0.0, 0.5, "a number of turns")
        if not isinstance(self.first_paid, bool):
            raise ValueError(f"{path}.first_paid must be true or false, got {self.first_paid!r}")
        if self.after is not None:
            check_number(f"{path}.after", self.after, 1e-9, 1e6, "rotations per episode (or null: from the start)")


@dataclass(frozen=True, kw_only=True)
class TurnShapingSettings:
    """The pair's net turning pays (``roto.envs.aids.turn_shaping``): carrying the balls round
    pays, a swing out and back does not.

    Attributes:
        per_turn: the reward per turn the magnitude of the pair's net turning this episode grows,
            given back as it shrinks (a full turn makes two swaps: 20 pays as much as their swap
            reward).
        lead: None: every turn is paid; else the paid turning stops this many turns ahead of half
            a turn per swap made, so spinning the pair without the balls trading places pays at
            most ``lead`` turns an episode.
        near: None: the turning pays wherever the pair is; else it pays only while the pair's
            centre is within ``near`` times half the targets' separation of their midpoint (a
            length each hand's targets give), and shrinking it is charged anywhere, so turning the
            pair off the targets earns nothing and no loop, in and out, earns anything.
        soft: with ``near``: beyond it the turning pays (near / offset)² of its reward (offset: the
            centre's distance from the midpoint in half separations) instead of nothing, so turning
            nearer the targets always pays more; shrinking is still charged in full anywhere.
        near_from: with ``near``: None: ``near`` from the start; else ``near`` starts at
            ``near_from`` and narrows to ``near`` as the training episodes' net turns (the running
            mean of their size, ``roto.envs.aids.episode_mean.Narrowing``) reach ``near_turns``:
            turning pays wherever the pair is while the policy learns to turn it, and near the
            targets once it does.
        near_turns: the training episodes' net turns at which ``near`` has narrowed from
            ``near_from`` to ``near``.
    """

    per_turn: float = 20.0
    lead: float | None = None
    near: float | None = None
    soft: bool = False
    near_from: float | None = None
    near_turns: float = 3.0

    def check(self, path: str, task: Any) -> None:
        _needs_parameter(path, task, "turn_reward", "a ball pair")
        check_number(f"{path}.per_turn", self.per_turn, 0.0, 1000.0, "a reward per turn")
        if self.lead is not None:
            check_number(f"{path}.lead", self.lead, 0.0, 100.0, "a number of turns (or null: unbounded)")
        if self.near is not None:
            check_number(
                f"{path}.near", self.near, 0.0, 100.0, "a number of half target separations (or null: anywhere)"
            )
        if not isinstance(self.soft, bool):
            raise ValueError(f"{path}.soft must be true or false, got {self.soft!r}")
        if self.soft and self.near is None:
            raise ValueError(
                f"{path}.soft needs {path}.near (the half target separations it falls off beyond), got near=None"
            )
        check_number(f"{path}.near_turns", self.near_turns, 1e-9, 1e6, "net turns per episode")
        if self.near_from is not None:
            if self.near is None:
                raise ValueError(f"{path}.near_from needs {path}.near (the value it narrows to), got near=None")
            check_number(f"{path}.near_from", self.near_from, self.near, 100.0, "half target separations from near")


@dataclass(frozen=True, kw_only=True)
class DropPenaltySettings:
    """A training episode that ends with the ball lost is charged (``roto.envs.aids.drop_penalty``).

    Attributes:
        per_drop: the reward charged on the control step an episode ends by losing the ball (the
            task's termination; an episode that runs its 10 s is not charged). 10 is one bounce's
            pay, so an episode that bounces once and loses the ball earns nothing.
    """

    per_drop: float = 10.0

    def check(self, path: str, task: Any) -> None:
        _needs_parameter(path, task, "drop_penalty", "a ball to lose", "bounce")
        check_number(f"{path}.per_drop", self.per_drop, 0.0, 1000.0, "a reward charged per lost ball")


@dataclass(frozen=True, kw_only=True)
class AidsConfig:
    """The aids section: one entry per aid, None where it is off (the benchmark: all None)."""

    replayed_starts: ReplayedStartsSettings | None = None
    tolerance: ToleranceSettings | None = None
    round_swaps: RoundSwapsSettings | None = None
    turn_shaping: TurnShapingSettings | None = None
    drop_penalty: DropPenaltySettings | None = None

    def active(self) -> dict[str, Any]:
        """{aid: its settings} of the aids that are on, in the section's order."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if getattr(self, f.name) is not None}

    def check(self, task: Any) -> None:
        """Raise ValueError naming the setting, its value and the valid range, for ``task``."""
        for name, settings in self.active().items():
            settings.check(f"aids.{name}", task)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """The section as plain data: the aids that are on only."""
        return {name: dataclasses.asdict(settings) for name, settings in self.active().items()}


AID_NAMES = tuple(f.name for f in dataclasses.fields(AidsConfig))
"""Every aid the section knows, in the order the env applies them."""


def parse_aids(data: Mapping[str, Any] | AidsConfig | None, where: str = "aids") -> AidsConfig:
    """The section from plain data ({aid: {setting: value}}; an aid mapped to None is off).

    Raises:
        ValueError naming an unknown aid or setting and the valid ones, or a mapping that is not one.
    """
    if isinstance(data, AidsConfig):
        return data
    if data is None:
        return AidsConfig()
    if not isinstance(data, Mapping):
        raise ValueError(f"{where} must be a mapping of aid names to settings, got {data!r}; aids: {list(AID_NAMES)}")
    hints = typing.get_type_hints(AidsConfig)
    kinds = {name: typing.get_args(hints[name])[0] for name in AID_NAMES}  # X of "X | None"
    built = {}
    for name, settings in data.items():
        if name not in kinds:
            raise ValueError(f"unknown training aid {where}.{name}; valid aids: {list(AID_NAMES)}")
        if settings is None or isinstance(settings, kinds[name]):
            built[name] = settings
            continue
        if not isinstance(settings, Mapping):
            raise ValueError(f"{where}.{name} must be a mapping of its settings, got {settings!r}")
        valid = [f.name for f in dataclasses.fields(kinds[name])]
        unknown = sorted(set(settings) - set(valid))
        if unknown:
            raise ValueError(f"unknown setting(s) {unknown} of {where}.{name}; valid settings: {valid}")
        try:
            built[name] = kinds[name](**settings)
        except TypeError:
            required = [f.name for f in dataclasses.fields(kinds[name]) if f.default is dataclasses.MISSING]
            raise ValueError(f"{where}.{name} needs {required}, got {dict(settings)!r}") from None
    return AidsConfig(**built)


LEGACY_FIELDS = {
    "replay_starts": ("replayed_starts", "bank"),
    "replay_share": ("replayed_starts", "share"),
    "replay_record_lead": ("replayed_starts", "record_lead"),
    "replay_record_capacity": ("replayed_starts", "record_capacity"),
    "tolerance_start": ("tolerance", "start"),
    "tolerance_target": ("tolerance", "target"),
    "swap_min_turn": ("round_swaps", "min_turn"),
    "turn_reward": ("turn_shaping", "per_turn"),
}
"""{env field of run configs and checkpoints of format 1: (aid, setting) of the aids section}."""
LEGACY_BANK_FOLDER = "benchmarks/results/baoding_reference/"
"""Where format 1's configs named the banks roto now ships (``roto/banks/<name>.npz``)."""
LEGACY_SWITCHES = {"replay_starts": None, "tolerance_start": 0.0, "swap_min_turn": 0.0, "turn_reward": 0.0}
"""The format-1 field that switched each aid on, at its off value."""


def aids_from_legacy_fields(env: Mapping[str, Any]) -> dict[str, Any]:
    """A stored env config of format 1 (aid settings as flat fields, ``replay_starts`` ...) in
    today's form (an ``aids`` section holding the aids it switched on; a bank roto now ships by
    its name)."""
    env = dict(env)
    flat = {name: env.pop(name) for name in LEGACY_FIELDS if name in env}
    on = {LEGACY_FIELDS[name][0] for name, off in LEGACY_SWITCHES.items() if flat.get(name, off) != off}
    aids: dict[str, dict[str, Any]] = {aid: {} for aid in AID_NAMES if aid in on}
    for name, value in flat.items():
        aid, setting = LEGACY_FIELDS[name]
        if name == "replay_starts" and str(value).startswith(LEGACY_BANK_FOLDER):  # a bank roto now ships
            value = str(value).removeprefix(LEGACY_BANK_FOLDER).removesuffix(".npz")
        if aid in aids:
            aids[aid][setting] = value
    if flat:
        env["aids"] = aids
    return env

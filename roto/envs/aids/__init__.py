"""Training aids (``roto.envs.aids.protocol``): what a config's aid fields build, in the order the
env applies them. Adding an aid: a module here with its ``TrainingAid`` subclass, one line in
``build_aids``, its config fields and tests (docs/developer.md)."""

from __future__ import annotations

from roto.envs.aids.event_recorder import RecordedEvents
from roto.envs.aids.protocol import AidHost, StepContext, TrainingAid
from roto.envs.aids.replayed_starts import ReplayedStarts
from roto.envs.aids.round_swaps import RoundSwaps
from roto.envs.aids.tolerance import ToleranceAid
from roto.envs.aids.turn_shaping import TurnShaping

__all__ = [
    "AidHost",
    "RecordedEvents",
    "ReplayedStarts",
    "RoundSwaps",
    "StepContext",
    "ToleranceAid",
    "TrainingAid",
    "TurnShaping",
    "build_aids",
]


def build_aids(host: AidHost) -> tuple[TrainingAid, ...]:
    """The aids ``host.config`` asks for (none for an evaluation env): replayed starts (a bank in
    ``replay_starts``), recorded own events (``replay_record_lead`` > 0, drawn by the replayed
    starts), the tolerance curriculum (``tolerance_start`` > 0), round swaps (``swap_min_turn`` > 0),
    turn shaping (``turn_reward`` > 0)."""
    config, aids = host.config, []
    replay = ReplayedStarts(host) if config.replay_starts is not None else None
    if replay is not None:
        aids.append(replay)
    if config.replay_record_lead > 0:  # the config check guarantees replayed starts beside it
        aids.append(replay.record_own_events(host))
    if config.tolerance_start > 0.0:
        aids.append(ToleranceAid(host))
    if config.swap_min_turn > 0.0:
        aids.append(RoundSwaps(host))
    if config.turn_reward > 0.0:
        aids.append(TurnShaping(host))
    return tuple(aids)

"""The aids an env's config switches on, built in the section's order (``AidsConfig``)."""

from __future__ import annotations

from roto.envs.aids.drop_penalty import DropPenalty
from roto.envs.aids.protocol import AidHost, TrainingAid
from roto.envs.aids.replayed_starts import ReplayedStarts
from roto.envs.aids.round_swaps import ArmedRoundSwaps, RoundSwaps
from roto.envs.aids.tolerance import ToleranceAid
from roto.envs.aids.turn_shaping import NarrowingTurnShaping, TurnShaping


def build_aids(host: AidHost) -> tuple[TrainingAid, ...]:
    """The aids ``host.config.aids`` switches on (none for an evaluation env): replayed starts,
    with the recorder of the envs' own events beside them when ``record_lead`` > 0, the tolerance
    curriculum, round swaps (armed part way with ``after``), turn shaping (its ``near`` narrowing with
    ``near_from``), the drop penalty."""
    section, aids = host.config.aids, []
    if section.replayed_starts is not None:
        replay = ReplayedStarts(host, section.replayed_starts)
        aids.append(replay)
        if section.replayed_starts.record_lead > 0:
            aids.append(replay.record_own_events(host, section.replayed_starts))
    if section.tolerance is not None:
        aids.append(ToleranceAid(host, section.tolerance))
    if section.round_swaps is not None:
        armed = section.round_swaps.after is not None
        aids.append((ArmedRoundSwaps if armed else RoundSwaps)(host, section.round_swaps))
    if section.turn_shaping is not None:
        narrowing = section.turn_shaping.near_from is not None
        aids.append((NarrowingTurnShaping if narrowing else TurnShaping)(host, section.turn_shaping))
    if section.drop_penalty is not None:
        aids.append(DropPenalty(host, section.drop_penalty))
    return tuple(aids)

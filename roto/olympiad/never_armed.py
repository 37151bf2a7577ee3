"""Round swaps that never armed: the same run as one without them.

Round swaps armed part way (``RoundSwapsSettings.after``) pay every swap until the training
episodes reach ``after`` rotations, exactly as no round swaps do (``roto.envs.aids.round_swaps``):
the aid changes nothing until it arms, and it arms for good. A run whose training record shows them
unarmed at its last env step therefore trained step for step as the run without them would have,
and as a run with round swaps armed no sooner (a larger or equal ``after``, any ``min_turn``) would
have. The staleness check and ``--adopt`` compare such a summary with the plan's round swaps in
place of its own; tables name the aid ``NEVER_ARMED_LABEL``. The record is the flag
``ARMED_METRIC`` that the armed aid logs into every training record of a cell summary.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from roto.envs.aids.round_swaps import ARMED_METRIC
from roto.envs.aids.settings import AidsConfig
from roto.rl.run_spec import RunSpec

NEVER_ARMED_LABEL = "round_swaps (never armed)"
"""The aid's name in tables and manifests for a run whose round swaps never armed."""


def never_armed(summary: Mapping[str, Any]) -> bool:
    """True where ``summary``'s training record shows armed round swaps unarmed up to its run's
    last env step: every record has ``ARMED_METRIC`` at 0, and the last is at or past the summary's
    ``env_steps``. False where the run had no armed round swaps (no flag), they armed, or the record
    stops short of the run's end (they may have armed after it), or any of these does not read as
    a list of records and numbers."""
    records, steps = summary.get("training"), summary.get("env_steps")
    if not isinstance(records, list) or not records or not all(isinstance(r, dict) for r in records):
        return False
    if any(record.get(ARMED_METRIC) != 0 for record in records):
        return False
    last = records[-1].get("env_steps")
    return all(isinstance(v, int) and not isinstance(v, bool) for v in (last, steps)) and last >= steps


def no_sooner(trained: AidsConfig, now: AidsConfig) -> bool:
    """Whether ``now``'s round swaps, beside ``trained``'s armed ones that never armed, would not
    have armed either: none at all, or armed at ``after`` no smaller than ``trained``'s."""
    if now.round_swaps is None:
        return True
    return now.round_swaps.after is not None and now.round_swaps.after >= trained.round_swaps.after


def aids_as_compared(trained: AidsConfig, now: AidsConfig, summary: Mapping[str, Any]) -> AidsConfig:
    """``trained`` (the aids ``summary``'s run trained with) to compare with ``now`` (a plan's):
    its round swaps replaced by ``now``'s where they never armed (``never_armed``) and ``now``'s
    would not have armed either (``no_sooner``); else ``trained`` as it is."""
    armed_part_way = trained.round_swaps is not None and trained.round_swaps.after is not None
    if armed_part_way and never_armed(summary) and no_sooner(trained, now):
        return dataclasses.replace(trained, round_swaps=now.round_swaps)
    return trained


def spec_as_compared(trained: RunSpec, now: RunSpec, summary: Mapping[str, Any]) -> RunSpec:
    """``trained`` with its aids as ``aids_as_compared`` gives them against ``now``'s."""
    aids = aids_as_compared(trained.env.aids, now.env.aids, summary)
    return dataclasses.replace(trained, env=dataclasses.replace(trained.env, aids=aids))


def aid_labels(names: list[str], summary: Mapping[str, Any]) -> list[str]:
    """``names`` (the aids a run trained with) with round swaps named ``NEVER_ARMED_LABEL`` where
    ``summary``'s record shows they never armed."""
    if not never_armed(summary):
        return names
    return [NEVER_ARMED_LABEL if name == "round_swaps" else name for name in names]

"""The env config's aids section: plain data in and out, strict names, every aid off by default,
and format-1 flat fields read into it."""

import pytest

from roto.envs.aids.settings import (
    AidsConfig,
    RoundSwapsSettings,
    aids_from_legacy_fields,
    parse_aids,
)
from roto.envs.config import EnvConfig


def test_the_section_reads_plain_data_and_writes_back_only_the_aids_that_are_on():
    aids = parse_aids({"round_swaps": {}, "tolerance": {"start": 0.02}, "turn_shaping": None})
    assert aids.active() == {"tolerance": aids.tolerance, "round_swaps": RoundSwapsSettings(min_turn=0.25)}
    assert aids.to_dict() == {
        "tolerance": {"start": 0.02, "target": 1.0, "by": "headline", "deadline": None},
        "round_swaps": {"min_turn": 0.25, "first_paid": False, "after": None},
    }
    assert parse_aids(aids.to_dict()) == aids and parse_aids(None) == AidsConfig() == parse_aids({})
    assert EnvConfig(task="baoding").aids == AidsConfig()  # the benchmark: none


@pytest.mark.parametrize(
    ("data", "pattern"),
    [
        ([1], r"aids must be a mapping of aid names to settings, got \[1\]; aids: \['replayed_starts'"),
        ({"tolerance": 0.02}, r"aids.tolerance must be a mapping of its settings, got 0.02"),
        ({"turn": {}}, r"unknown training aid aids.turn; valid aids: \[.*'turn_shaping', 'drop_penalty'\]"),
        ({"round_swaps": {"turns": 1}}, r"unknown setting\(s\) \['turns'\] of aids.round_swaps; valid settings"),
    ],
)
def test_bad_sections_are_refused_naming_the_aid_and_the_valid_ones(data, pattern):
    with pytest.raises(ValueError, match=pattern):
        EnvConfig(task="baoding", aids=data)


def test_format_1_flat_fields_switch_on_only_the_aids_they_set():
    replay = {"replay_starts": None, "replay_share": 0.0, "replay_record_lead": 0, "replay_record_capacity": 1024}
    off = {"task": "bounce", **replay, "tolerance_start": 0.0, "tolerance_target": 1.0, "swap_min_turn": 0.0}
    assert aids_from_legacy_fields(off) == {"task": "bounce", "aids": {}}
    on = {**off, "task": "baoding", "swap_min_turn": 0.25, "replay_starts": "b.npz"}
    assert aids_from_legacy_fields(on)["aids"] == {
        "replayed_starts": {"bank": "b.npz", "share": 0.0, "record_lead": 0, "record_capacity": 1024},
        "round_swaps": {"min_turn": 0.25},
    }
    assert aids_from_legacy_fields({"task": "bounce", "aids": {}}) == {"task": "bounce", "aids": {}}  # today's form

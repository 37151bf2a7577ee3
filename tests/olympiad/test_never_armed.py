import json
import pathlib

import pytest

from roto.olympiad.adopt import adopt_cells
from roto.olympiad.cell import cell_spec
from roto.olympiad.never_armed import ARMED_METRIC, NEVER_ARMED_LABEL, never_armed
from roto.olympiad.plan import load_plan
from roto.olympiad.reference_tables import training_aids
from roto.olympiad.staleness import stale_cells, summary_differences

ROOT = pathlib.Path(__file__).resolve().parents[2]
TEMPLATE = ROOT / "experiments" / "baoding_hold_every_hand" / "results" / "baoding-allegro-blind-ppo-seed1.json"
"""An Allegro run of baoding_cpu_hold (round swaps armed after 2 rotations) whose round swaps never armed."""

ROUND_SWAPS = {
    "armed": [],
    "without": ["env.aids.round_swaps=null"],
    "later": ["env.aids.round_swaps.after=3"],
    "sooner": ["env.aids.round_swaps.after=1"],
    "from_start": ["env.aids.round_swaps.after=null"],
}
"""Plans training the Allegro's blind Baoding with baoding_cpu_hold and these overrides."""


def write_plan(folder: pathlib.Path, name: str, seeds: str = "[1]"):
    path = folder / f"{name}.yaml"
    path.write_text(
        "steps: 40960\nnum_envs: 8\nthreads: 1\nvariants:\n  ppo:\n    baoding: {agent_cfg: "
        f"experiments/baoding_configs/baoding_cpu_hold.yaml, overrides: {json.dumps(ROUND_SWAPS[name])}}}\n"
        f"grids:\n  - {{tasks: [baoding], robots: [allegro], obs: [blind], variants: [ppo], seeds: {seeds}}}\n"
    )
    return load_plan(str(path))


def template(armed_at: int | None = None) -> dict:
    """The template summary; with ``armed_at``, its round swaps armed from that training record on."""
    summary = json.loads(TEMPLATE.read_text())
    if armed_at is not None:
        for record in summary["training"][armed_at:]:
            record[ARMED_METRIC] = 1.0
    return summary


@pytest.fixture
def plans(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)  # the plans name the agent config by its path in the repository
    return {name: write_plan(tmp_path, name) for name in ROUND_SWAPS}


def test_never_armed_needs_the_flag_at_zero_up_to_the_runs_last_env_step():
    summary = template()
    assert never_armed(summary)
    assert not never_armed(template(armed_at=-1))  # armed at the last record
    assert not never_armed({**summary, "training": summary["training"][:-1]})  # the record stops short
    unflagged = [{k: v for k, v in record.items() if k != ARMED_METRIC} for record in summary["training"]]
    assert not never_armed({**summary, "training": unflagged})  # no armed round swaps: nothing to say
    assert not never_armed({**summary, "training": []})
    for unreadable in ({"training": {"a": 1}}, {"training": ["a"]}, {"env_steps": "all"}, {"env_steps": None}):
        assert not never_armed({**summary, **unreadable}), unreadable


@pytest.mark.parametrize("recorded", ["spec", "training_aids"])
def test_round_swaps_that_never_armed_are_no_difference_where_the_plans_would_not_have_armed_either(plans, recorded):
    armed = plans["armed"]
    cell = armed.cells[0]
    summary = template()
    if recorded == "spec":  # as summaries record it now; else only the aids, as the template does
        summary["spec"] = cell_spec(armed, cell).to_dict()
    for same in ("armed", "without", "later"):
        assert summary_differences(plans[same], cell, summary) == {}, same
    for other in ("sooner", "from_start"):  # these would have armed earlier: another run
        assert summary_differences(plans[other], cell, summary) != {}, other
    assert summary_differences(plans["without"], cell, template(armed_at=40)) != {}  # armed at 4 M: another run


def test_a_never_armed_cell_is_adopted_by_the_plan_without_round_swaps_and_its_tables_say_so(plans, tmp_path):
    armed, without = write_plan(tmp_path, "armed", "[1, 2]"), plans["without"]
    source, target = tmp_path / "armed_results", tmp_path / "without_results"
    source.mkdir()
    for seed, summary in ((1, template()), (2, template(armed_at=60))):
        summary.update(plan="armed", seed=seed)
        (source / f"baoding-allegro-blind-ppo-seed{seed}.json").write_text(json.dumps(summary))
    assert adopt_cells(armed, source, without, target) == ["baoding-allegro-blind-ppo-seed1"]
    adopted = json.loads((target / "baoding-allegro-blind-ppo-seed1.json").read_text())
    assert adopted["training_aids"]["round_swaps"]["after"] == 2  # recorded as it trained
    assert training_aids(adopted) == f"replayed_starts, {NEVER_ARMED_LABEL}, tolerance, turn_shaping"
    assert training_aids(template(armed_at=60)) == "replayed_starts, round_swaps, tolerance, turn_shaping"
    assert stale_cells(without, target) == {}


def test_the_study_without_round_swaps_took_from_the_benchmark_only_runs_whose_round_swaps_never_armed():
    study = ROOT / "experiments" / "baoding_without_round_swaps"
    plan, results = load_plan(str(study / "without_round_swaps.yaml")), study / "results"
    taken = [json.loads(p.read_text()) for p in sorted(results.glob("*.json"))]
    taken = [s for s in taken if (s.get("adopted_from") or {}).get("plan") == "benchmark"]
    assert taken and all(never_armed(s) and NEVER_ARMED_LABEL in training_aids(s) for s in taken)
    assert stale_cells(plan, results) == {}

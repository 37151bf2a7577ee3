import json
import pathlib

import pytest

from roto.cli import main
from roto.jobs.storage import find_study
from roto.olympiad.adopt import adopt_cells
from roto.olympiad.cell import cell_spec, run_cell
from roto.olympiad.plan import load_plan
from roto.olympiad.staleness import stale_cells, summary_differences
from roto.olympiad.worker import cell_status, run_olympiad_worker, study_name
from roto.rl.run_spec import RunSpec
from tests.olympiad.toy_plan import write_toy_plan
from tests.rl.toy_env import ToyEnv

ROOT = pathlib.Path(__file__).resolve().parents[2]


def with_bounce_metric(path: pathlib.Path) -> dict:
    """The toy env's summary at ``path`` rewritten with the Bounce metric ``roto results`` reads
    (0 bounces in every record); returned."""
    summary = json.loads(path.read_text())
    for record in (summary["final"], summary["best"], *summary["evaluations"]):
        record["bounces_mean"] = 0.0
    path.write_text(json.dumps(summary))
    return summary


@pytest.fixture
def trained(tmp_path):
    """The toy plan's first cell trained (2 updates), and the plan file rewritten to train every
    cell with 2 PPO epochs instead of 1."""
    plan_path = write_toy_plan(tmp_path, updates=2, seeds=(0,))
    plan, root = load_plan(str(plan_path)), tmp_path / "runs"
    results, cell = root / "toy" / "results", plan.cells[0]
    run_cell(plan, cell, root / "toy" / cell.name, results, "aaa1111", ToyEnv)
    plan_path.write_text(plan_path.read_text().replace("ppo.epochs=1", "ppo.epochs=2"))
    return plan, load_plan(str(plan_path)), root, results, cell


def test_a_summary_records_the_spec_it_trained_and_matches_its_plan(trained):
    plan, _, _, results, cell = trained
    summary = json.loads((results / f"{cell.name}.json").read_text())
    assert RunSpec.from_dict(summary["spec"]) == cell_spec(plan, cell)
    assert stale_cells(plan, results) == {}


def test_a_summary_trained_otherwise_than_the_plan_now_is_stale_and_no_worker_starts_beside_it(trained, capsys):
    _, changed, root, results, cell = trained
    kept = (results / f"{cell.name}.json").read_text()
    assert stale_cells(changed, results) == {cell.name: {"agent.ppo.epochs": (1, 2)}}
    assert cell_status(changed, str(root), results, None)[cell.name] == "stale"
    with pytest.raises(ValueError) as refused:
        run_olympiad_worker(changed, str(root), results, env_factory=ToyEnv)
    message = str(refused.value)
    assert f"{cell.name}: agent.ppo.epochs: 1 -> 2" in message and "move each summary aside" in message
    assert find_study(root / "toy", study_name(changed), None) is None  # refused before the study is made
    assert (results / f"{cell.name}.json").read_text() == kept

    toy = str(root.parent / "toy.yaml")
    assert main(["olympiad", toy, "--root", str(root), "--workers", "2"]) == 2
    assert "agent.ppo.epochs: 1 -> 2" in capsys.readouterr().err
    # the cells without a summary train; the stale one is left to its owner
    assert run_olympiad_worker(changed, str(root), results, env_factory=ToyEnv, only=["baoding-*"]) == 2


def test_the_dry_run_lists_a_stale_cell_with_the_settings_it_trained_otherwise(tmp_path, capsys):
    committed = ROOT / "benchmarks" / "results" / "benchmark" / "cells" / "baoding-shadow-blind-ppo-seed0.json"
    summary = json.loads(committed.read_text())
    summary.pop("spec", None)
    summary["training_aids"] = {**summary["training_aids"], "turn_shaping": {"per_turn": 10}}
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / committed.name).write_text(json.dumps(summary))
    argv = ["olympiad", "benchmark", "--root", str(tmp_path), "--results", str(tmp_path / "results")]
    assert main([*argv, "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert f"{committed.stem:<52} stale [5 M]\n    trained otherwise: env.aids: {{" in out
    assert "0 done, 1 stale (not trained again), 79 left; time left:" in out
    assert main([*argv, "--only", "baoding-shadow-blind-*"]) == 2  # one stale cell among those chosen
    assert f"{committed.stem}: env.aids: " in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results"]  # nothing made
    out = ["--out", str(tmp_path / "tables")]
    assert main(["results", str(tmp_path / "results"), "--plan", "benchmark", *out]) == 2
    assert "a table of plan 'benchmark' would show them as its cells" in capsys.readouterr().err
    assert not (tmp_path / "tables").exists()
    assert main(["results", str(tmp_path / "results"), *out]) == 0  # the summaries' own table


def test_a_summary_without_a_recorded_spec_is_compared_by_the_training_aids_it_records(trained):
    plan, _, _, results, cell = trained
    summary = json.loads((results / f"{cell.name}.json").read_text())
    del summary["spec"]  # as written before summaries recorded it
    assert summary_differences(plan, cell, summary) == {}  # no aid on either side
    drop = {"drop_penalty": {"per_drop": 10.0}}
    assert summary_differences(plan, cell, {**summary, "training_aids": drop}) == {"env.aids": (drop, {})}
    del summary["training_aids"]
    assert summary_differences(plan, cell, summary) == {}  # nothing recorded to compare


@pytest.mark.parametrize(
    ("text", "said"),
    [("[]", "should be a JSON object, found list"), ('{"spec": {"env": {}}}', "its recorded spec does not read"),
     ('{"training_aids": {"warp_drive": {}}}', "unknown training aid aids.warp_drive"),
     ("{", "is not valid JSON at line 1, column 2")],
)  # fmt: skip
def test_a_summary_that_does_not_read_is_refused_naming_its_file(trained, text, said):
    plan, _, _, results, cell = trained
    (results / f"{cell.name}.json").write_text(text)
    with pytest.raises(ValueError, match=said) as refused:
        stale_cells(plan, results)
    assert f"{cell.name}.json" in str(refused.value)


def test_a_longer_budget_alone_is_no_difference(trained):
    plan, _, _, results, _ = trained
    longer = load_plan(str(write_toy_plan(results.parents[2], updates=4, seeds=(0,))))
    assert longer.steps > plan.steps and stale_cells(longer, results) == {}


def test_a_cell_is_adopted_by_the_spec_its_summary_records_not_by_its_plans_settings_now(trained, tmp_path):
    plan, changed, _, results, cell = trained
    with_bounce_metric(results / f"{cell.name}.json")
    (tmp_path / "bench").mkdir()
    bench = load_plan(str(write_toy_plan(tmp_path / "bench", updates=2, seeds=(0,))))  # the cell as it trained
    # its plan now trains 2 epochs; the summary records the 1 it trained, as the bench cell does
    assert adopt_cells(changed, results, bench, tmp_path / "bench_results") == [cell.name]
    assert adopt_cells(plan, results, changed, tmp_path / "again") == []  # 1 epoch is not 2: no match


def test_every_committed_benchmark_summary_trained_what_the_benchmark_plan_trains_now():
    """A change to a packaged recipe that the benchmark's finished cells did not train with fails
    here, before a table would mix the two."""
    assert stale_cells(load_plan("benchmark"), ROOT / "benchmarks" / "results" / "benchmark" / "cells") == {}


def test_adopting_a_summary_whose_recorded_spec_does_not_read_is_refused_naming_it(trained, tmp_path):
    plan, _, _, results, cell = trained
    path = results / f"{cell.name}.json"
    path.write_text(json.dumps({**with_bounce_metric(path), "spec": {"env": {}}}))
    with pytest.raises(ValueError, match=f"cell summary {cell.name}: its recorded spec does not read"):
        adopt_cells(plan, results, plan, tmp_path / "elsewhere")
    assert not (tmp_path / "elsewhere").exists()

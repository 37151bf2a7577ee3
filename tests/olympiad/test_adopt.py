import json
import pathlib

import pytest

from roto.cli import main
from roto.olympiad.adopt import adopt_cells
from roto.olympiad.plan import load_plan

ROOT = pathlib.Path(__file__).resolve().parents[2]
TEMPLATE = (
    ROOT / "experiments" / "baoding_armed_round_swaps" / "results" / "baoding-shadow-blind-armed_round-seed5.json"
)
HALF_TURN_SHAPING = "env.aids.turn_shaping.per_turn=10"
"""A setting baoding_cpu does not have (it pays 20 per turn)."""


def write_plan(path: pathlib.Path, variant: str, entry: str, seeds: str, steps: int = 40960) -> pathlib.Path:
    path.write_text(
        f"steps: {steps}\nnum_envs: 8\nthreads: 1\nvariants:\n  {variant}:\n    baoding: {entry}\n"
        f"grids:\n  - {{tasks: [baoding], robots: [shadow], obs: [blind], variants: [{variant}], seeds: {seeds}}}\n"
    )
    return path


def write_summary(folder: pathlib.Path, variant: str, seed: int, plan: str, rotations: float) -> None:
    summary = json.loads(TEMPLATE.read_text())
    summary.update(variant=variant, seed=seed, plan=plan)
    summary["best"] = {**summary["best"], "round_rotations_mean": rotations}
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"baoding-shadow-blind-{variant}-seed{seed}.json").write_text(json.dumps(summary))


@pytest.fixture
def plans(tmp_path):
    """A study that trains baoding_cpu with a halved turn shaping as an override, and a benchmark
    whose config file is baoding_cpu with the same turn shaping written in: the same runs, two names."""
    config = tmp_path / "half_turn_shaping.yaml"
    config.write_text("extends: baoding_cpu\ntraining_aids:\n  turn_shaping: {per_turn: 10}\n")
    study = write_plan(
        tmp_path / "study.yaml", "armed", f"{{agent_cfg: baoding_cpu, overrides: [{HALF_TURN_SHAPING}]}}", "[0, 2, 3]"
    )
    bench = write_plan(tmp_path / "bench.yaml", "ppo", f"{{agent_cfg: {config}}}", "[0, 1, 2]")
    return load_plan(str(study)), load_plan(str(bench)), tmp_path


def test_a_study_cell_that_trains_exactly_a_benchmark_cell_counts_as_it_and_says_where_it_came_from(plans):
    study, bench, tmp_path = plans
    source, target = tmp_path / "study_results", tmp_path / "bench_results"
    for seed, rotations in ((0, 12.5), (2, 3.25), (3, 9.0)):
        write_summary(source, "armed", seed, "study", rotations)
    write_summary(target, "ppo", 2, "bench", 7.75)  # a cell the benchmark has already: kept
    assert adopt_cells(study, source, bench, target) == ["baoding-shadow-blind-ppo-seed0"]  # seed 3: no such cell
    adopted = json.loads((target / "baoding-shadow-blind-ppo-seed0.json").read_text())
    assert (adopted["variant"], adopted["plan"], adopted["best"]["round_rotations_mean"]) == ("ppo", "bench", 12.5)
    assert adopted["agent"]["label"] == str(tmp_path / "half_turn_shaping.yaml")
    assert adopted["adopted_from"]["plan"] == "study"
    assert adopted["adopted_from"]["cell"] == "baoding-shadow-blind-armed-seed0"
    assert (
        json.loads((target / "baoding-shadow-blind-ppo-seed2.json").read_text())["best"]["round_rotations_mean"] == 7.75
    )
    assert adopt_cells(study, source, bench, target) == []  # done now: nothing copied twice


def test_a_cell_that_differs_in_any_setting_or_its_budget_is_not_adopted(plans, tmp_path):
    study, _, _ = plans
    source = tmp_path / "study_results"
    write_summary(source, "armed", 0, "study", 12.5)
    plain = load_plan(str(write_plan(tmp_path / "plain.yaml", "ppo", "{agent_cfg: baoding_cpu}", "[0]")))
    longer = write_plan(
        tmp_path / "longer.yaml", "ppo", f"{{agent_cfg: baoding_cpu, overrides: [{HALF_TURN_SHAPING}]}}", "[0]", 81920
    )
    for other in (plain, load_plan(str(longer))):
        assert adopt_cells(study, source, other, tmp_path / f"{other.name}_results") == []
        assert not (tmp_path / f"{other.name}_results").exists()


def test_a_study_folder_may_hold_another_plans_summaries_which_are_passed_over(plans):
    study, bench, tmp_path = plans
    write_summary(tmp_path / "study_results", "armed", 0, "study", 12.5)
    write_summary(tmp_path / "study_results", "armed", 2, "untuned", 3.25)  # the same variant, another plan
    assert adopt_cells(study, tmp_path / "study_results", bench, tmp_path / "bench_results") == [
        "baoding-shadow-blind-ppo-seed0"
    ]
    assert sorted(path.name for path in (tmp_path / "bench_results").iterdir()) == [
        "baoding-shadow-blind-ppo-seed0.json"
    ]


@pytest.mark.parametrize(
    ("summaries", "message"),
    [  # an adoptable summary beside the bad one: nothing is written
        (
            [("armed", 0, "study"), ("elsewhere", 2, "study")],
            r"plan 'study' has no variant 'elsewhere'; valid variants: \['armed'\]",
        ),
        # a folder given with the wrong plan would be judged by that plan's settings
        (
            [("armed", 0, "elsewhere")],
            r"no summary in .* was trained by plan 'study' \(its summaries' plans: \['elsewhere'\]\)",
        ),
    ],
)
def test_a_folder_of_another_plan_or_an_unknown_variant_is_refused_naming_it_and_nothing_is_written(
    plans, summaries, message
):
    study, bench, tmp_path = plans
    for variant, seed, trained_by in summaries:
        write_summary(tmp_path / "study_results", variant, seed, trained_by, 1.0)
    with pytest.raises(ValueError, match=message):
        adopt_cells(study, tmp_path / "study_results", bench, tmp_path / "bench_results")
    assert not (tmp_path / "bench_results").exists()


def test_the_olympiad_command_adopts_and_trains_nothing(plans, capsys):
    _, _, tmp_path = plans
    write_summary(tmp_path / "study_results", "armed", 0, "study", 12.5)
    argv = ["olympiad", str(tmp_path / "bench.yaml"), "--root", str(tmp_path / "runs"), "--results"]
    adopt = ["--adopt", str(tmp_path / "study.yaml"), str(tmp_path / "study_results")]
    assert main([*argv, str(tmp_path / "bench_results"), *adopt]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["adopted"] == ["baoding-shadow-blind-ppo-seed0"] and printed["from"] == "study"
    assert not (tmp_path / "runs").exists()
    assert main([*argv, str(tmp_path / "bench_results"), "--dry-run"]) == 0
    assert "baoding-shadow-blind-ppo-seed0" in capsys.readouterr().out.split("done")[0]

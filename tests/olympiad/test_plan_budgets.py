"""A grid's own ``steps``: its cells' budget in the plan, the run they train and the dry run."""

import pytest

from roto.cli import main
from roto.olympiad.cell import cell_spec
from roto.olympiad.plan import load_plan

VARIANTS = "variants:\n  ppo:\n    bounce: {agent_cfg: bounce_cpu_quickstart}\nsteps: 4096\n"
SHORT = "  - {tasks: [bounce], robots: [shadow], obs: [blind], variants: [ppo], seeds: [0, 1]}\n"
LONG = "  - {tasks: [bounce], robots: [allegro], obs: [blind], variants: [ppo], seeds: [0], steps: 8192}\n"


def write(tmp_path, text):
    path = tmp_path / "plan.yaml"
    path.write_text(VARIANTS + "grids:\n" + text)
    return str(path)


def test_a_grids_steps_are_its_cells_budget_and_the_others_keep_the_plans(tmp_path):
    plan = load_plan(write(tmp_path, SHORT + LONG))
    budgets = {cell.name: plan.steps_for(cell) for cell in plan.cells}
    assert budgets == {
        "bounce-shadow-blind-ppo-seed0": 4096,
        "bounce-allegro-blind-ppo-seed0": 8192,
        "bounce-shadow-blind-ppo-seed1": 4096,
    }
    assert {cell.name: cell_spec(plan, cell).steps for cell in plan.cells} == budgets  # what each cell trains


def test_the_dry_run_names_each_cells_budget_when_they_differ(tmp_path, capsys):
    path = write(tmp_path, SHORT + LONG)
    folders = ["--root", str(tmp_path / "runs"), "--results", str(tmp_path / "results")]
    assert main(["olympiad", path, "--dry-run", *folders]) == 0
    out = capsys.readouterr().out
    assert "3 cells, env steps per cell as listed" in out
    assert "bounce-allegro-blind-ppo-seed0" in out and "not started [0.008192 M]" in out


@pytest.mark.parametrize(
    ("grids", "message"),
    [
        (LONG.replace("8192", "0"), r"grids\[0\]: steps must be an integer >= 1, got 0"),
        (LONG.replace("8192", "'10M'"), r"steps must be an integer >= 1, got '10M'"),
        (LONG + LONG.replace("8192", "4096"), r"grids\[1\] gives cell bounce-allegro-blind-ppo-seed0 4096 env steps"),
        (SHORT.replace("seeds:", "stepz: 1, seeds:"), r"unknown keys \['stepz'\]; valid keys: \['obs', .*'steps'"),
    ],
)
def test_a_bad_grid_budget_is_refused_naming_it(tmp_path, grids, message):
    with pytest.raises(ValueError, match=message):
        load_plan(write(tmp_path, grids))

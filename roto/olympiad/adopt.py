"""Cells two plans share: a finished cell of one plan (a study) whose run is exactly a cell of
another (the benchmark) counts as that cell, so that no seed is trained twice.

"Exactly" is the run spec (``cell_spec``): task, hand, obs mode, agent config and overrides, training
aids, seed, env count and backend, compared setting by setting, and the env-step budget (the C
threads may differ: they step the same worlds to the same states). The summary is
copied under the other plan's cell name with its ``variant``, ``plan`` and ``agent`` as that plan
would have written them, and ``adopted_from`` naming the plan, cell and agent it was trained as;
everything it measured is kept as it is.
"""

from __future__ import annotations

import json
import pathlib

from roto.olympiad.cell import agent_record, cell_spec, summary_path
from roto.olympiad.plan import Cell, Plan
from roto.olympiad.results import read_summaries
from roto.result_files import write_text_atomic


def same_run(source_plan: Plan, source: Cell, target_plan: Plan) -> Cell | None:
    """The cell of ``target_plan`` that trains exactly what ``source`` trains in ``source_plan``, or
    None. Only cells of the same task, hand, obs mode and seed are compared (their specs, built and
    checked; a difference of any setting or of the budget is no match)."""
    spec = cell_spec(source_plan, source)
    for cell in target_plan.cells:
        if (cell.task, cell.robot, cell.obs, cell.seed) != (source.task, source.robot, source.obs, source.seed):
            continue
        same_budget = target_plan.steps_for(cell) == source_plan.steps_for(source)
        if same_budget and cell_spec(target_plan, cell).differences(spec) == {}:
            return cell
    return None


def adopt_cells(
    source_plan: Plan, source_results: pathlib.Path, target_plan: Plan, target_results: pathlib.Path
) -> list[str]:
    """Copy each summary in ``source_results`` (cells of ``source_plan``) that is exactly a cell of
    ``target_plan`` into ``target_results`` under that cell's name, unless the cell is done there;
    returns the target cells written. A summary another plan trained, or of a variant
    ``source_plan`` does not have, is refused, naming it."""
    written = []
    for summary in read_summaries(source_results):
        source = Cell(*(summary[key] for key in ("task", "robot", "obs", "variant", "seed")))
        where = f"summary {source.name} in {str(source_results)!r}"
        if summary["plan"] != source_plan.name:
            raise ValueError(
                f"{where} was trained by plan {summary['plan']!r}, not {source_plan.name!r}; give its plan"
            )
        if source.variant not in source_plan.variants:
            raise ValueError(
                f"{where}: plan {source_plan.name!r} has no variant {source.variant!r}; "
                f"valid variants: {sorted(source_plan.variants)}"
            )
        target = same_run(source_plan, source, target_plan)
        if target is None or summary_path(target_results, target).is_file():
            continue
        adopted = {
            **summary,
            "variant": target.variant,
            "plan": target_plan.name,
            "agent": agent_record(target_plan, target),
            "adopted_from": {"plan": source_plan.name, "cell": source.name, "agent": summary.get("agent")},
        }
        target_results.mkdir(parents=True, exist_ok=True)
        write_text_atomic(summary_path(target_results, target), json.dumps(adopted, indent=1))
        written.append(target.name)
    return written

"""Cells two plans share: a finished cell of one plan (a study) whose run is exactly a cell of
another (the benchmark) counts as that cell, so that no seed is trained twice.

"Exactly" is the run spec (the one the summary records it trained; for a summary written before
summaries recorded it, the source plan's ``cell_spec``): task, hand, obs mode, agent config and
overrides, training aids, seed, env count and backend, compared setting by setting, and the
env-step budget (the C threads may differ: they step the same worlds to the same states; round swaps
that never armed count as the target's where its would not have armed either,
``roto.olympiad.never_armed``). The summary is
copied under the other plan's cell name with its ``variant``, ``plan`` and ``agent`` as that plan
would have written them, and ``adopted_from`` naming the plan, cell and agent it was trained as;
everything it measured is kept as it is.
"""

from __future__ import annotations

import json
import pathlib

from roto.olympiad.cell import agent_record, cell_spec, summary_path
from roto.olympiad.never_armed import spec_as_compared
from roto.olympiad.plan import Cell, Plan
from roto.olympiad.results import read_summaries
from roto.olympiad.staleness import recorded_spec
from roto.result_files import write_text_atomic
from roto.rl.run_spec import RunSpec


def same_run(
    source_plan: Plan, source: Cell, target_plan: Plan, trained: RunSpec | None = None, summary: dict | None = None
) -> Cell | None:
    """The cell of ``target_plan`` that trains exactly what ``source`` trains in ``source_plan``, or
    None. Only cells of the same task, hand, obs mode and seed are compared (their specs, built and
    checked; a difference of any setting or of the budget is no match). ``trained``: the spec the
    source's summary records it trained (None for a summary without one: the source plan's now);
    ``summary``: the source's summary, whose training record tells whether its round swaps armed."""
    spec = trained or cell_spec(source_plan, source)
    for cell in target_plan.cells:
        if (cell.task, cell.robot, cell.obs, cell.seed) != (source.task, source.robot, source.obs, source.seed):
            continue
        now = cell_spec(target_plan, cell)
        compared = spec if summary is None else spec_as_compared(spec, now, summary)
        if target_plan.steps_for(cell) == spec.steps and compared.differences(now) == {}:
            return cell
    return None


def adopt_cells(
    source_plan: Plan, source_results: pathlib.Path, target_plan: Plan, target_results: pathlib.Path
) -> list[str]:
    """Copy each summary in ``source_results`` that ``source_plan`` trained and that is exactly a cell
    of ``target_plan`` into ``target_results`` under that cell's name, unless the cell is done there;
    returns the target cells written. Summaries of other plans in the folder (a study's plans may
    share one) are passed over; a folder none of whose summaries ``source_plan`` trained, or a
    summary of a variant it does not have, is refused naming it, before anything is written."""
    summaries = read_summaries(source_results)
    own = [summary for summary in summaries if summary["plan"] == source_plan.name]
    if summaries and not own:
        raise ValueError(
            f"no summary in {str(source_results)!r} was trained by plan {source_plan.name!r} (its "
            f"summaries' plans: {sorted({summary['plan'] for summary in summaries})}); give their plan"
        )
    adoptions = []
    for summary in own:
        source = Cell.of_summary(summary)
        if source.variant not in source_plan.variants:
            raise ValueError(
                f"summary {source.name} in {str(source_results)!r}: plan {source_plan.name!r} has no variant "
                f"{source.variant!r}; valid variants: {sorted(source_plan.variants)}"
            )
        target = same_run(source_plan, source, target_plan, recorded_spec(summary, source.name), summary)
        if target is not None and not summary_path(target_results, target).is_file():
            adoptions.append((target, adopted_summary(summary, source_plan, source, target_plan, target)))
    if adoptions:
        target_results.mkdir(parents=True, exist_ok=True)
    for target, adopted in adoptions:
        write_text_atomic(summary_path(target_results, target), json.dumps(adopted, indent=1))
    return [target.name for target, _ in adoptions]


def adopted_summary(summary: dict, source_plan: Plan, source: Cell, target_plan: Plan, target: Cell) -> dict:
    """``summary`` as ``target_plan`` would have written it for ``target``, with ``adopted_from``
    naming the plan, cell and agent it was trained as; every measurement kept as it is."""
    return {
        **summary,
        "variant": target.variant,
        "plan": target_plan.name,
        "agent": agent_record(target_plan, target),
        "adopted_from": {"plan": source_plan.name, "cell": source.name, "agent": summary.get("agent")},
    }

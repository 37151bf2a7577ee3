"""Whether a finished cell's summary still answers its plan.

A worker counts a cell with a summary as done. Should the plan change what the cell trains after
it finished (another agent config, other training aids, another env count), the summary would
stand in the table for a run the plan no longer describes. Each summary records the run spec it
trained (``spec``; a summary written before that records its training aids, ``training_aids``),
so the plan check can compare it, setting by setting, with what the plan trains the cell with now
(``roto.rl.run_spec.RunSpec.differences``: the budget and the C threads aside, since a finished
run may be continued to a longer budget and on other threads). Round swaps that never armed are no
difference where the plan's would not have armed either (``roto.olympiad.never_armed``): the runs
are the same.
"""

from __future__ import annotations

import pathlib
from typing import Any

from roto.envs.aids.settings import parse_aids
from roto.olympiad.cell import cell_spec, summary_path
from roto.olympiad.never_armed import aids_as_compared, spec_as_compared
from roto.olympiad.plan import Cell, Plan
from roto.result_files import read_json
from roto.rl.run_spec import RunSpec

SHOWN = 3
"""Settings named per cell in a refusal (the rest are counted)."""


def summary_differences(
    plan: Plan, cell: Cell, summary: dict[str, Any], where: str = "(given)"
) -> dict[str, tuple[Any, Any]]:
    """{setting: (the summary's value, the plan's)} where the summary's run trained otherwise than
        ``plan`` trains ``cell`` now: every setting of the recorded ``spec``, or of a summary without
        one the training aids it records (``env.aids``); {} where it matches as far as it records (round
    swaps that never armed as ``roto.olympiad.never_armed.aids_as_compared`` compares them).
        ValueError naming ``where`` (the summary) where its spec or aids do not read."""
    now = cell_spec(plan, cell)
    trained = recorded_spec(summary, where)
    if trained is not None:
        return spec_as_compared(trained, now, summary).differences(now)
    if "training_aids" not in summary:
        return {}
    try:
        aids = aids_as_compared(parse_aids(summary["training_aids"]), now.env.aids, summary)
    except ValueError as error:
        raise ValueError(f"cell summary {where}: its recorded training aids do not read ({error})") from None
    return {} if aids == now.env.aids else {"env.aids": (summary["training_aids"], now.env.aids.to_dict())}


def stale_cells(plan: Plan, results: pathlib.Path) -> dict[str, dict[str, tuple[Any, Any]]]:
    """{cell name: its ``summary_differences``} for each of ``plan``'s cells whose summary in
    ``results`` trained otherwise than the plan trains it now."""
    stale = {}
    for cell in plan.cells:
        path = summary_path(results, cell)
        if path.is_file() and (differences := recorded_differences(plan, cell, path)):
            stale[cell.name] = differences
    return stale


def recorded_differences(plan: Plan, cell: Cell, path: pathlib.Path) -> dict[str, tuple[Any, Any]]:
    """``summary_differences`` of the summary at ``path``; ValueError naming the file where it is not
    a JSON object or its ``spec`` or ``training_aids`` do not read as a run spec and aids."""
    summary = read_json(path, "cell summary")
    if not isinstance(summary, dict):
        raise ValueError(f"cell summary {str(path)!r} should be a JSON object, found {type(summary).__name__}")
    return summary_differences(plan, cell, summary, repr(str(path)))


def recorded_spec(summary: dict[str, Any], where: str) -> RunSpec | None:
    """The run spec ``summary`` records it trained, None where it records none (written before
    summaries did); ValueError naming ``where`` where it does not read as one."""
    if "spec" not in summary:
        return None
    try:
        return RunSpec.from_dict(summary["spec"])
    except (KeyError, TypeError, ValueError) as error:
        raise ValueError(f"cell summary {where}: its recorded spec does not read ({error})") from None


def describe(differences: dict[str, tuple[Any, Any]]) -> str:
    """``key: summary's value -> plan's value`` for the first ``SHOWN`` settings, and how many more."""
    shown = [f"{key}: {old!r} -> {new!r}" for key, (old, new) in list(differences.items())[:SHOWN]]
    more = len(differences) - SHOWN
    return "; ".join(shown) + (f"; and {more} more" if more > 0 else "")


def refuse_stale(plan: Plan, results: pathlib.Path, remedy: str) -> None:
    """Raise ValueError naming every cell of ``plan`` whose summary in ``results`` trained otherwise
    than the plan trains it now, the settings that differ and ``remedy`` (the ways on for the
    caller); nothing is changed."""
    stale = stale_cells(plan, results)
    if stale:
        lines = [f"  {name}: {describe(differences)}" for name, differences in stale.items()]
        raise ValueError(
            f"{len(stale)} cell(s) of plan {plan.name!r} have a summary in {str(results)!r} trained with other "
            "settings than the plan trains them with now (summary's -> plan's):\n" + "\n".join(lines) + f"\n{remedy}"
        )


def retrain_remedy(plan: Plan, root: str) -> str:
    """What a worker refusing stale cells says to do."""
    return (
        "to train them again, move each summary aside and its run directory "
        f"({root}/{plan.name}/<cell>, which cannot continue under other settings); or restore the plan's settings"
    )

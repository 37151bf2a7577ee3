"""``roto results``' page: results.md (the lead measures, each policy's table, the path metrics,
the probabilities of improvement), the CSVs and the curves, from a folder of cell summaries."""

from __future__ import annotations

import pathlib

from roto.cli_errors import check_output_path
from roto.olympiad.manifest import write_manifest
from roto.olympiad.path_results import lead_measure_scores, lead_section, path_metric_table
from roto.olympiad.plan import Plan
from roto.olympiad.results import (
    current_tasks,
    improvements,
    markdown_table,
    page_label,
    plot_curves,
    read_summaries,
    scores_by_cell,
    variant_agents,
    write_csv,
)
from roto.olympiad.staleness import refuse_stale
from roto.olympiad.submission import with_submissions
from roto.result_files import write_text_atomic


def results_markdown(summaries: list[dict], plan: str = "") -> str:
    """results.md of ``summaries``: the lead measures, each policy's table, the path metrics and the
    probabilities of improvement, on the lead measures of the best policies as the tables lead
    (what ``write_results`` writes, without the CSVs and curves)."""
    agents = variant_agents(summaries, plan or summaries[0].get("plan", ""))
    current = current_tasks(summaries)
    md = [f"# Olympiad results ({page_label(summaries, plan)})", "", *lead_section(summaries, agents, current)]
    for policy in ("final", "best"):
        heading = f"## {policy} policy: the task's headline metric (Baoding: roto's count) per 10 s episode"
        heading += ", mean ± std over seeds"
        md += [heading, "", markdown_table(scores_by_cell(summaries, policy), agents, current), ""]
    md += path_metric_table(summaries)
    pairs = improvements(lead_measure_scores(summaries))
    if pairs:
        md += ["## Probability of improvement (best policies, lead measure; variants with two or more seeds)", ""]
        md += [f"- {t} / {r} / {o}: P({x} > {y}) = {p:.2f}" for t, r, o, x, y, p in pairs]
    return "\n".join(md) + "\n"


def write_results(
    source: str | pathlib.Path, out: str | pathlib.Path, plan: Plan | None = None, submissions: str | None = None
) -> dict[str, str]:
    """results.md, results_*.csv, manifest.csv and curve PNGs in ``out`` (``--out``: a folder, made
    with its missing parents; refused, before anything is written, where it cannot be one) from the
    summaries in ``source`` and, beside them, the submissions in the folder ``submissions``;
    ``plan``, if given, names the pages and the manifest's configs."""
    summaries = read_summaries(source)
    if plan is not None:  # a table under the plan's name shows only what the plan trains now
        refuse_stale(
            plan,
            pathlib.Path(source),
            f"a table of plan {plan.name!r} would show them as its cells: "
            "move them aside, or restore the plan's settings",
        )
    if submissions is not None:
        summaries = with_submissions(summaries, submissions)
    name = plan.name if plan else ""
    out = check_output_path(out, "--out", kind="dir")
    out.mkdir(parents=True, exist_ok=True)
    write_manifest(summaries, out / "manifest.csv", plan)
    for policy in ("final", "best"):
        write_csv(scores_by_cell(summaries, policy), out / f"results_{policy}.csv", policy)
    write_text_atomic(out / "results.md", results_markdown(summaries, name))
    plots = plot_curves(summaries, out, name)
    return {"markdown": str(out / "results.md"), "plots": [str(p) for p in plots], "cells": len(summaries)}

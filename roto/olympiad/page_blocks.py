"""A markdown page's generated blocks (docs/results.md, the README, experiments' pages): each
between ``<!-- roto results: KIND SOURCE[,SOURCE...] [plan=PLAN[,PLAN...]] [names=NAME[,NAME...]]
[baseline=VARIANT] -->`` and ``<!-- /roto results -->``, a table of
``roto.olympiad.reference_tables`` made from the cell summaries in its source folders.
``refresh_blocks`` makes every block's table again; ``check_blocks`` finds an opening that does
not read as one, or a block left open.
"""

from __future__ import annotations

import dataclasses
import pathlib
import re
from collections.abc import Callable

from roto.olympiad.plan import Plan, load_plan
from roto.olympiad.reference_tables import (
    config_label,
    orderings_table,
    overview_table,
    seeds_table,
    task_table,
    variants_table,
)
from roto.olympiad.results import read_summaries


def _variants(summaries: list[dict], plan: Plan | None, options: dict[str, str]) -> str:
    if "baseline" not in options:
        raise ValueError(
            "a variants block names its baseline variant: <!-- roto results: variants SOURCES baseline=VARIANT -->"
        )
    return variants_table(summaries, options["baseline"], plan)


TABLES: dict[str, Callable[[list[dict], Plan | None, dict[str, str]], str]] = {
    "bounce": lambda summaries, plan, options: task_table(summaries, "bounce", plan),
    "baoding": lambda summaries, plan, options: task_table(summaries, "baoding", plan),
    "overview": lambda summaries, plan, options: overview_table(summaries),
    "orderings": lambda summaries, plan, options: orderings_table(summaries),
    "seeds": lambda summaries, plan, options: seeds_table(summaries),
    "variants": _variants,
}
"""The kinds of generated block a page may hold, each a table of its source's summaries."""
BLOCK = re.compile(r"(<!-- roto results: (\S+) (\S+)((?: \w+=\S+)*) -->\n)(.*?)(<!-- /roto results -->)", re.DOTALL)
OPTIONS = ("plan", "names", "baseline")
"""What a block's opening may set after its sources: ``plan=PLAN[,PLAN...]`` (the plans whose
configs label the rows), ``names=NAME[,NAME...]`` (one per source: the variant name its cells
show under, so that two studies' cells of one variant name stand side by side; ``plan=`` then
names each source's own plan), ``baseline=VARIANT`` (the variants table's baseline)."""


def joined_plans(names: str) -> Plan:
    """The plans ``names`` (comma-separated names or files) as one whose variants are all of theirs,
    so that rows from several studies each name their own config; ValueError where two of them
    train a variant of the same name differently."""
    plans = [load_plan(name) for name in names.split(",")]
    variants = dict(plans[0].variants)
    for plan in plans[1:]:
        for name, variant in plan.variants.items():
            if variants.setdefault(name, variant) != variant:
                raise ValueError(f"plans {names!r} both have a variant {name!r}, trained differently; name one plan")
    return dataclasses.replace(plans[0], variants=variants)


def named_summaries(sources: dict[str, list[dict]], names: str, plans: str | None) -> list[dict]:
    """The summaries of each source folder (``sources``: folder -> its summaries) under the variant
    name ``names`` gives it (one per folder, comma-separated), each labelled with the config its
    folder's plan trains it with (``plans``, one per folder; without, the label its summary records)
    and keeping only the cells of the variant that plan trains: a study whose cells share their
    variant's name with another's (the benchmark's ``ppo``) is set beside it under a name of its
    own. ValueError where the counts differ or a folder holds cells of more than one variant."""
    names_list = names.split(",")
    plan_list = [load_plan(name) for name in plans.split(",")] if plans else [None] * len(sources)
    if not len(names_list) == len(plan_list) == len(sources):
        raise ValueError(
            f"names={names!r}{f' and plan={plans!r}' if plans else ''} must name one for each of the "
            f"{len(sources)} sources {','.join(sources)!r}"
        )
    named = []
    for (folder, summaries), name, plan in zip(sources.items(), names_list, plan_list, strict=True):
        kept = [s for s in summaries if plan is None or s["variant"] in plan.variants]
        variants = sorted({s["variant"] for s in kept})
        if len(variants) > 1:
            raise ValueError(f"source {folder!r} holds cells of variants {variants}: names= gives a folder one name")
        for s in kept:
            agent = {**(s.get("agent") or {}), "label": config_label(s, plan)}
            named.append({**s, "variant": name, "agent": agent})
    return named


def _options(opening: str, text: str) -> dict[str, str]:
    """A block's ``key=value`` options; ValueError naming an unknown one."""
    options = dict(item.split("=", 1) for item in text.split())
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise ValueError(f"generated block {opening.strip()!r}: unknown option {unknown[0]!r}; valid: {list(OPTIONS)}")
    return options


def refresh_blocks(text: str, root: str | pathlib.Path) -> str:
    """``text`` with every generated block's table made again from its source folders (relative to
    ``root``, the repository; several joined by commas); ValueError naming an unknown kind or
    option, or a folder without summaries."""

    def table(match: re.Match) -> str:
        opening, kind, source, options = match.group(1, 2, 3, 4)
        if kind not in TABLES:
            raise ValueError(f"generated block {opening.strip()!r}: unknown kind {kind!r}; valid: {sorted(TABLES)}")
        options = _options(opening, options)
        sources = {folder: read_summaries(pathlib.Path(root) / folder) for folder in source.split(",")}
        if "names" in options:
            summaries, plan = named_summaries(sources, options["names"], options.get("plan")), None
        else:
            plan = joined_plans(options["plan"]) if "plan" in options else None
            summaries = [s for folder_summaries in sources.values() for s in folder_summaries]
        return f"{opening}{TABLES[kind](summaries, plan, options)}\n{match.group(6)}"

    return BLOCK.sub(table, text)


OPENING = re.compile(r"^<!-- roto results:", re.MULTILINE)


def check_blocks(text: str, page: str) -> int:
    """How many generated blocks ``page`` (its ``text``) holds; ValueError naming the page when it
    holds none, or the line of an opening that does not read as one (a typo in it) or of a block
    not closed before the next block opens, where refreshing would leave a stale table unnoticed."""

    def line(index: int) -> int:
        return text.count("\n", 0, index) + 1

    blocks = [match.span() for match in BLOCK.finditer(text)]
    starts = {start for start, _ in blocks}
    for index in (match.start() for match in OPENING.finditer(text)):
        if index in starts:
            continue
        enclosing = [start for start, end in blocks if start < index < end]
        if enclosing:
            raise ValueError(
                f"page {page!r}, line {line(enclosing[0])}: the generated block opened there has no "
                f"'<!-- /roto results -->' before the next block opens, at line {line(index)}"
            )
        opening = text[index:].split("\n", 1)[0]
        raise ValueError(
            f"page {page!r}, line {line(index)}: {opening!r} does not open a generated block; write "
            "'<!-- roto results: KIND SOURCE[ option=value ...] -->', the table, then '<!-- /roto results -->'"
        )
    if not blocks:
        raise ValueError(
            f"page {page!r} holds no generated block ('<!-- roto results: KIND SOURCE -->' ... "
            "'<!-- /roto results -->'): nothing in it to refresh"
        )
    return len(blocks)

"""Every committed results page is what its summaries generate now: a page left behind when its
summaries, a plan's labels or the page's layout change fails here. A page in ``.../tables/...``
is made from the summaries at the same place under ``results`` (the benchmark's: ``cells``):
regenerate it with ``roto results <summaries> --out <tables>``."""

import pathlib

import pytest

from roto.olympiad.page_blocks import OPENING, check_blocks, refresh_blocks
from roto.olympiad.results import read_summaries
from roto.olympiad.results_page import results_markdown

ROOT = pathlib.Path(__file__).resolve().parents[2]


def summaries_of(page: pathlib.Path) -> pathlib.Path | None:
    """The folder of summaries a committed page is made from, None if it has none."""
    parts = page.parent.relative_to(ROOT).parts
    if "tables" not in parts:
        return None
    i = len(parts) - 1 - parts[::-1].index("tables")
    for name in ("results", "cells"):
        folder = ROOT.joinpath(*parts[:i], name, *parts[i + 1 :])
        if folder.is_dir():
            return folder
    return None


PAGES = sorted(
    page
    for top in ("benchmarks/results", "experiments")
    for page in (ROOT / top).rglob("results.md")
    if summaries_of(page) is not None
)


PLANS = {"benchmarks/results/benchmark/tables": "benchmark"}
"""Pages whose columns are named by a plan (``roto results ... --plan``); the others by their summaries."""


@pytest.mark.parametrize("page", PAGES, ids=[str(p.parent.relative_to(ROOT)) for p in PAGES])
def test_a_committed_page_is_what_its_summaries_generate(page):
    summaries = read_summaries(summaries_of(page))
    plan = PLANS.get(str(page.parent.relative_to(ROOT)), "")
    assert page.read_text() == results_markdown(summaries, plan), f"regenerate {page.parent}"


GENERATED = sorted(
    str(path.relative_to(ROOT))
    for path in [ROOT / "README.md", *(ROOT / "docs").glob("*.md"), *(ROOT / "experiments").rglob("*.md")]
    if OPENING.search(path.read_text())  # a block's opening at a line's start, not one quoted in prose
)


@pytest.mark.parametrize("page", GENERATED)
def test_the_generated_tables_of_a_page_are_what_their_summaries_generate(page):
    text = (ROOT / page).read_text()
    assert check_blocks(text, page) >= 1  # every opening of the page reads as a block, each closed
    assert refresh_blocks(text, ROOT) == text, f"run: roto results --pages {page}"


def test_the_pages_with_generated_tables_are_found():
    assert {"README.md", "docs/results.md", "experiments/baoding_turn_shaping/README.md"} <= set(GENERATED)


def test_the_pages_are_found():
    found = {str(page.parent.relative_to(ROOT)) for page in PAGES}
    assert {"benchmarks/results/benchmark/tables", "experiments/baoding_v1/tables/baoding_v1_cpu"} <= found
    assert len(PAGES) >= 10

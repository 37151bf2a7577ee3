"""Every committed results page is what its summaries generate now: a page left behind when its
summaries, a plan's labels or the page's layout change fails here (regenerate it with
``roto results <folder> --out <folder>_tables``)."""

import pathlib

import pytest

from roto.olympiad.results import read_summaries
from roto.olympiad.results_page import results_markdown

RESULTS = pathlib.Path(__file__).resolve().parents[2] / "benchmarks" / "results"
PAGES = sorted(p for p in RESULTS.glob("*_tables/results.md") if (RESULTS / p.parent.name[: -len("_tables")]).is_dir())


@pytest.mark.parametrize("page", PAGES, ids=[p.parent.name for p in PAGES])
def test_a_committed_page_is_what_its_summaries_generate(page):
    summaries = read_summaries(RESULTS / page.parent.name[: -len("_tables")])
    assert page.read_text() == results_markdown(summaries), f"regenerate {page.parent}"


def test_the_pages_are_found():
    assert len(PAGES) >= 10

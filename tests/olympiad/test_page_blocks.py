import json

import pytest

from roto.cli import main
from roto.olympiad.page_blocks import check_blocks, refresh_blocks
from roto.olympiad.reference_tables import overview_table
from tests.olympiad.test_reference_tables import SUMMARIES, VARIANT_SUMMARIES, baoding, write_folder


def test_pages_refresh_their_generated_blocks_from_one_or_more_folders(tmp_path, monkeypatch, capsys):
    write_folder(tmp_path / "a", SUMMARIES[:5])
    write_folder(tmp_path / "b", SUMMARIES[5:])
    page = tmp_path / "page.md"
    page.write_text("# x\n\n<!-- roto results: overview a,b -->\nstale\n<!-- /roto results -->\n\nprose\n")
    monkeypatch.chdir(tmp_path)
    assert main(["results", "--pages", "page.md"]) == 0
    assert json.loads(capsys.readouterr().out) == {"pages": ["page.md"], "changed": ["page.md"]}
    text = page.read_text()
    assert "stale" not in text and overview_table(SUMMARIES) in text and text.endswith("\n\nprose\n")
    assert refresh_blocks(text, tmp_path) == text
    assert main(["results", "--pages", "page.md"]) == 0 and '"changed": []' in capsys.readouterr().out
    page.write_text("<!-- roto results: pie a -->\n<!-- /roto results -->\n")
    assert main(["results", "--pages", "page.md"]) == 2
    valid = "['baoding', 'bounce', 'orderings', 'overview', 'seeds', 'variants']"
    assert f"unknown kind 'pie'; valid: {valid}" in capsys.readouterr().err


def test_pages_that_cannot_be_refreshed_are_refused_naming_the_page_and_nothing_is_written(
    tmp_path, monkeypatch, capsys
):
    write_folder(tmp_path / "a", SUMMARIES[:5])
    good = "<!-- roto results: overview a -->\nstale\n<!-- /roto results -->\n"
    (tmp_path / "good.md").write_text(good)
    (tmp_path / "folder.md").mkdir()
    (tmp_path / "prose.md").write_text("# no table here; `<!-- roto results: KIND SOURCE -->` in prose\n")
    (tmp_path / "typo.md").write_text(good + "\n<!-- roto results: overview -->\n<!-- /roto results -->\n")
    (tmp_path / "unclosed.md").write_text("<!-- roto results: overview a -->\nstale\n\n" + good)
    monkeypatch.chdir(tmp_path)
    refused = {
        "missing.md": "page 'missing.md' does not exist",
        "folder.md": "page 'folder.md' cannot be read: it is a folder; give a file",
        "prose.md": "page 'prose.md' holds no generated block",
        "typo.md": "page 'typo.md', line 5: '<!-- roto results: overview -->' does not open a generated block",
        "unclosed.md": "page 'unclosed.md', line 1: the generated block opened there has no '<!-- /roto results -->' "
        "before the next block opens, at line 4",
    }
    for page, expected in refused.items():
        assert main(["results", "--pages", "good.md", page]) == 2, page
        err = capsys.readouterr().err
        assert expected in err and len(err.strip().splitlines()) == 1, (page, err)
        assert (tmp_path / "good.md").read_text() == good  # the page before it is left as it was
    assert check_blocks(good, "good.md") == 1


@pytest.mark.parametrize("flags", [["x", "--pages", "p.md"], ["--pages", "p.md", "--out", "o"]])
def test_pages_stand_alone(flags, capsys):
    assert main(["results", *flags]) == 2
    assert "refreshes the pages' generated tables; give it alone" in capsys.readouterr().err


def test_a_variants_block_needs_its_baseline_and_known_options(tmp_path):
    write_folder(tmp_path / "s", VARIANT_SUMMARIES)
    text = "<!-- roto results: variants s baseline=base -->\nold\n<!-- /roto results -->\n"
    fresh = refresh_blocks(text, tmp_path)
    assert "old" not in fresh and "| baoding | shadow | blind | bank |" in fresh
    with pytest.raises(ValueError, match="names its baseline variant"):
        refresh_blocks("<!-- roto results: variants s -->\n<!-- /roto results -->\n", tmp_path)
    with pytest.raises(ValueError, match=r"unknown option 'baseln'; valid: \['plan', 'names', 'baseline'\]"):
        refresh_blocks("<!-- roto results: variants s baseln=base -->\n<!-- /roto results -->\n", tmp_path)


def plan_file(path, variants: dict[str, str]):
    """A one-cell-per-variant Baoding plan at ``path``: variant name -> its agent config line."""
    lines = ["steps: 1000", "variants:"]
    lines += [f"  {name}:\n    baoding: {{agent_cfg: {agent}}}" for name, agent in variants.items()]
    lines += [
        "grids:",
        f"  - {{tasks: [baoding], robots: [shadow], obs: [blind], variants: [{', '.join(variants)}], seeds: [0]}}",
    ]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_a_block_labels_each_variant_from_whichever_of_its_plans_trains_it(tmp_path):
    """Rows from two studies name each one's own config, not the one their summaries recorded."""
    write_folder(tmp_path / "s", VARIANT_SUMMARIES)
    one = plan_file(tmp_path / "one.yaml", {"base": "baoding_cpu_v1", "other_seeds": "baoding_cpu_v1"})
    two = plan_file(tmp_path / "two.yaml", {"bank": "baoding_cpu", "other_seeds": "baoding_cpu_v1"})
    text = f"<!-- roto results: variants s plan={one},{two} baseline=base -->\n<!-- /roto results -->\n"
    rows = [line.split(" | ") for line in refresh_blocks(text, tmp_path).splitlines() if line.startswith("| baoding")]
    assert [(row[3], row[4]) for row in rows] == [
        ("base", "`baoding_cpu_v1`"),
        ("bank", "`baoding_cpu`"),
        ("other_seeds", "`baoding_cpu_v1`"),
    ]
    only_bank = plan_file(tmp_path / "three.yaml", {"base": "baoding_cpu_v1", "bank": "baoding_cpu"})
    text = f"<!-- roto results: variants s plan={only_bank} baseline=base -->\n<!-- /roto results -->\n"
    rows = [line.split(" | ") for line in refresh_blocks(text, tmp_path).splitlines() if line.startswith("| baoding")]
    assert [row[3] for row in rows] == ["base", "bank"]  # other_seeds: a variant no plan of the block trains
    clash = plan_file(tmp_path / "clash.yaml", {"base": "baoding_cpu"})
    with pytest.raises(ValueError, match="both have a variant 'base', trained differently"):
        refresh_blocks(
            f"<!-- roto results: variants s plan={one},{clash} baseline=base -->\n<!-- /roto results -->\n", tmp_path
        )


def test_two_studies_whose_cells_share_a_variant_name_stand_side_by_side_under_names_of_their_own(tmp_path):
    """The benchmark's cells and a study's retraining of them are both ``ppo``: ``names=`` gives each
    folder's cells a name, so the variants table pairs them seed by seed, each row labelled from its
    own folder's plan."""
    write_folder(tmp_path / "recipe", [baoding("base", s, r, r) for s, r in ((0, 10.0), (1, 12.0), (2, 14.0))])
    write_folder(tmp_path / "study", [baoding("base", s, r, r) for s, r in ((0, 11.0), (1, 11.0), (2, 16.0), (3, 9.0))])
    one = plan_file(tmp_path / "one.yaml", {"base": "baoding_cpu"})
    two = plan_file(tmp_path / "two.yaml", {"base": "baoding_cpu_v1"})
    text = (
        f"<!-- roto results: variants recipe,study plan={one},{two} names=with,without baseline=with -->\n"
        "<!-- /roto results -->\n"
    )
    rows = [line.split(" | ") for line in refresh_blocks(text, tmp_path).splitlines() if line.startswith("| baoding")]
    assert [(row[3], row[4], row[5]) for row in rows] == [
        ("with", "`baoding_cpu`", "0, 1, 2"),
        ("without", "`baoding_cpu_v1`", "0, 1, 2, 3"),
    ]
    # paired on seeds 0-2: +1, -1, +2 -> +0.7; seed 3 has no pair
    assert rows[1][9] == "0, 1, 2" and rows[1][10].startswith("+0.7 [") and rows[1][11] == "2 / 1 |"
    without_plans = text.replace(f" plan={one},{two}", "")
    labels = [line.split(" | ")[4] for line in refresh_blocks(without_plans, tmp_path).splitlines()[3:-1]]
    assert labels == ["`cfg_base`", "`cfg_base`"]  # the label each summary records
    with pytest.raises(ValueError, match=r"names='with' must name one for each of the 2 sources 'recipe,study'"):
        refresh_blocks(without_plans.replace("names=with,without", "names=with"), tmp_path)
    write_folder(tmp_path / "mixed", VARIANT_SUMMARIES)
    with pytest.raises(ValueError, match=r"source 'mixed' holds cells of variants \['bank', 'base', 'other_seeds'\]"):
        refresh_blocks(without_plans.replace("recipe,study", "recipe,mixed"), tmp_path)

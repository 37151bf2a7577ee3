import csv
import json

from roto.cli import main
from roto.olympiad.manifest import manifest_rows
from roto.olympiad.plan import load_plan
from roto.olympiad.reference_tables import overview_table, seeds_table, task_table


def summary(task, robot, obs, variant, seed, best, **extra):
    return {
        "task": task,
        "robot": robot,
        "obs": obs,
        "variant": variant,
        "seed": seed,
        "plan": "toy",
        "commit": "abc1234",
        "evaluations": [],
        "final": best,
        "best": best,
        **extra,
    }


BOUNCES = [10.0, 20.0, 30.0, 100.0]
SUMMARIES = [
    *[summary("bounce", "shadow", "blind", "ppo", s, {"bounces_mean": b}) for s, b in enumerate(BOUNCES)],
    summary("bounce", "allegro", "state", "ppo", 0, {"bounces_mean": 4.5}, task_version=0),
    *[
        summary(
            "baoding",
            "shadow",
            "blind",
            "turn",
            s,
            {"rotations_mean": r, "round_rotations_mean": r - 1},
            agent={"label": "baoding_cpu_shadow + turn", "roto_agent": None},
            training_aids={"turn_shaping": {"per_turn": 20.0}, "tolerance": {}},
        )
        for s, r in ((0, 4.0), (1, 6.0))
    ],
]


def rows_of(table: str) -> dict[tuple[str, str], list[str]]:
    rows = [line.strip("|").split(" | ") for line in table.splitlines()[2:]]
    return {(row[0].strip(), row[1].strip()): [cell.strip() for cell in row] for row in rows}


def test_a_task_table_gives_each_hand_and_mode_its_statistics_seeds_and_references():
    table = task_table(SUMMARIES, "bounce")
    assert table.splitlines()[0].startswith("| hand | obs | agent config | training aids | seeds | bounces: mean ± std")
    shadow = rows_of(table)[("shadow", "blind")]
    # 10, 20, 30, 100: mean 40, population std sqrt(1250) = 35.4, IQM the mean of 20 and 30
    assert shadow[2:8] == ["`ppo`", "not recorded", "0, 1, 2, 3", "40.0 ± 35.4", shadow[6], "10.0, 20.0, 30.0, 100.0"]
    assert shadow[6].startswith("25.0 [") and shadow[-2:] == ["27.9", "v1 PPO 69; 2.0 about 80"]
    allegro = rows_of(table)[("allegro", "state")]
    assert allegro[5:8] == ["4.5", "", "4.5"] and allegro[-2:] == ["11.8", ""]  # one seed: no spread, no IQM
    assert list(rows_of(table)) == [("shadow", "blind"), ("allegro", "state")]  # the hand registry's order


def test_baoding_leads_with_round_rotations_and_names_roto_s_count_and_the_aids_beside():
    table = task_table(SUMMARIES, "baoding")
    assert "| round_rotations: mean ± std | IQM [95 % CI] | per seed | roto's rotations |" in table.splitlines()[0]
    row = rows_of(table)[("shadow", "blind")]
    assert row[2:9] == [
        "`baoding_cpu_shadow + turn`",
        "tolerance, turn_shaping",
        "0, 1",
        "4.0 ± 1.0",
        "",
        "3.0, 5.0",
        "5.0 ± 1.0",
    ]


def test_a_plan_names_each_hands_config_and_aids():
    ppo = [summary("bounce", r, "blind", "ppo", 0, {"bounces_mean": 1.0}) for r in ("shadow", "orca")]
    rows = rows_of(task_table(ppo, "bounce", load_plan("benchmark")))
    assert rows[("shadow", "blind")][2:4] == ["`bounce_cpu_quickstart`", "none"]
    assert rows[("orca", "blind")][2] == "`bounce_cpu_orca`"


def test_the_overview_is_a_few_short_lines():
    table = overview_table(SUMMARIES)
    lines = table.splitlines()
    assert lines[0] == "| hand | task | blind | state |"
    assert lines[2] == "| shadow | bounce | 40.0 (n=4) |  |"
    assert lines[3] == "| shadow | baoding | 4.0 (n=2) |  |"  # Baoding's round rotations
    assert lines[4] == "| allegro | bounce |  | 4.5 (n=1) |" and len(lines) == 5


def test_the_overview_of_the_whole_table_keeps_ten_lines_under_an_80_character_header():
    lead = {"bounce": "bounces_mean", "baoding": "round_rotations_mean"}
    whole = [
        summary(task, robot, obs, "ppo", 0, {lead[task]: 1.0, "rotations_mean": 1.0})
        for task in ("bounce", "baoding")
        for robot in ("shadow", "shadow_lite", "allegro", "orca")
        for obs in ("blind", "state", "proprio")
    ]
    lines = overview_table(whole).splitlines()
    assert lines[0] == "| hand | task | blind | state | proprio |" and len(lines[0]) < 80
    assert len(lines) == 10 and lines[-1] == "| orca | baoding | 1.0 (n=1) | 1.0 (n=1) | 1.0 (n=1) |"


def write_folder(path, summaries):
    path.mkdir()
    for s in summaries:
        (path / f"{s['task']}-{s['robot']}-{s['obs']}-{s['variant']}-seed{s['seed']}.json").write_text(json.dumps(s))


def test_the_manifest_names_each_cells_config_aids_commit_and_task_version(tmp_path):
    rows = {row["cell"]: row for row in manifest_rows(SUMMARIES)}
    turn = rows["baoding-shadow-blind-turn-seed1"]
    assert turn["config"] == "baoding_cpu_shadow + turn" and turn["training_aids"] == "tolerance, turn_shaping"
    assert turn["task_version"] == "not recorded" and rows["bounce-allegro-state-ppo-seed0"]["task_version"] == "0"
    assert turn["commit"] == "abc1234" and list(rows) == sorted(rows)
    assert turn["trained_by"] == "not recorded"  # a summary written before the record
    resumed = summary("bounce", "orca", "blind", "ppo", 0, {"bounces_mean": 1.0})
    resumed["trained_by"] = [{"commit": "aaa1111", "from_env_steps": 0}, {"commit": "abc1234", "from_env_steps": 64}]
    assert manifest_rows([resumed])[0]["trained_by"] == "aaa1111 from 0; abc1234 from 64"
    checked = {**resumed, "task_version": 0, "task_version_check": "rollouts at aaa1111 bit-identical"}
    assert manifest_rows([checked])[0]["task_version"] == "0 (rollouts at aaa1111 bit-identical)"
    write_folder(tmp_path / "cells", SUMMARIES)
    assert main(["results", str(tmp_path / "cells"), "--out", str(tmp_path / "out")]) == 0
    written = list(csv.DictReader((tmp_path / "out" / "manifest.csv").open()))
    assert [row["cell"] for row in written] == list(rows)


def test_orderings_give_both_gaps_with_intervals_and_name_the_pair_that_breaks_the_papers_order():
    from roto.olympiad.reference_tables import orderings_table

    def mode(obs, values, robot="shadow"):
        return [summary("bounce", robot, obs, "ppo", s, {"bounces_mean": b}) for s, b in enumerate(values)]

    proprio = mode("proprio", [5.0] * 3)
    state = mode("state", [50.0, 60.0, 70.0])
    lines = orderings_table(SUMMARIES + proprio + state).splitlines()
    assert len(lines) == 3  # the Allegro has no blind or proprio agent: no row
    cells = [cell.strip() for cell in lines[2].strip("|").split(" | ")]
    assert cells[:5] == ["bounce", "shadow", "60.0 (3)", "40.0 (4)", "5.0 (3)"]
    assert cells[5] == "+20.0" and cells[6].startswith("[") and cells[7] == "+35.0" and cells[8].startswith("[")
    assert cells[9] == "holds"
    low_state = mode("state", [1.0, 2.0])  # two seeds: no interval; state below blind breaks the order
    cells = [
        cell.strip()
        for cell in orderings_table(SUMMARIES + proprio + low_state).splitlines()[2].strip("|").split(" | ")
    ]
    assert cells[5:7] == ["-38.5", "needs three seeds each"] and cells[9] == "state < blind"
    both = orderings_table(mode("state", [1.0]) + mode("blind", [2.0]) + mode("proprio", [3.0]))
    assert both.splitlines()[2].endswith("| state < blind; blind < proprio |")


def test_orderings_give_touchs_effect_before_the_state_based_agents_are_in():
    """A hand with blind and proprio-only seeds but no state-based one: its row, the missing mode
    named, touch's effect with its interval, the part of the order measured."""
    from roto.olympiad.reference_tables import orderings_table

    def mode(obs, values):
        return [summary("bounce", "orca", obs, "ppo", s, {"bounces_mean": b}) for s, b in enumerate(values)]

    (row,) = orderings_table(mode("blind", [10.0, 12.0, 14.0]) + mode("proprio", [5.0] * 3)).splitlines()[2:]
    cells = [cell.strip() for cell in row.strip("|").split(" | ")]
    assert cells[2:8] == ["none", "12.0 (3)", "5.0 (3)", "", "", "+7.0"] and cells[8].startswith("[")
    assert cells[9] == "blind ≥ proprio (no state)"
    (row,) = orderings_table(mode("state", [1.0] * 3) + mode("blind", [2.0] * 3)).splitlines()[2:]
    assert row.endswith("| none | -1.0 | [-1.0, -1.0] |  |  | state < blind |")
    assert len(orderings_table(mode("blind", [2.0] * 3)).splitlines()) == 2  # blind alone: no row


def test_each_baoding_seed_gets_its_row_with_the_first_rounds_reaching_1_and_5():
    from roto.olympiad.reference_tables import seeds_table

    curve = [
        {"env_steps": 1_000_000, "round_rotations_mean": 0.5},
        {"env_steps": 2_000_000, "round_rotations_mean": 1.5},
    ]
    best = {"round_rotations_mean": 3.0, "round_rotations_std": 0.25, "rotations_mean": 4.0, "net_turns_mean": 3.5}
    one = summary(
        "baoding", "shadow", "blind", "turn", 7, best, evaluations=curve, env_steps=2_000_000, train_wall_s=600
    )
    lines = seeds_table([one, SUMMARIES[0]]).splitlines()  # Bounce has no row: it leads with its headline metric
    assert lines[0].startswith("| cell | seed | round_rotations | roto's rotations | net_turns | travelled_turns |")
    row = (
        "| shadow / blind / turn | 7 | **3.00** ± 0.25 | 4.00 | 3.50 | not measured | round | 2.00 M | never | 2.0 M |"
    )
    assert lines[2] == row + " 10 min |"
    assert len(lines) == 3


def baoding_seed(seed, rotations, net_turns):
    best = {"rotations_mean": rotations, "net_turns_mean": net_turns, "round_rotations_mean": min(rotations, net_turns)}
    return summary("baoding", "allegro", "blind", "mix", seed, best)


def test_baoding_tables_count_the_seeds_that_go_round_swing_or_never_swap():
    # seed 0 goes round (net turns 0.9 of its rotations), 1 swings (0.25 net turns), 2 makes half a
    # rotation per episode, 3 is exactly at 0.8 of its rotations
    seeds = [
        baoding_seed(0, 10.0, 9.0),
        baoding_seed(1, 12.0, 0.25),
        baoding_seed(2, 0.5, 0.5),
        baoding_seed(3, 5.0, 4.0),
    ]
    table = task_table(seeds, "baoding")
    assert "| per seed | seeds by path | roto's rotations |" in table.splitlines()[0]
    assert rows_of(table)[("allegro", "blind")][8] == "round 2, no swaps 1, swing 1"
    kinds = [line.split(" | ")[6] for line in seeds_table(seeds).splitlines()[2:]]
    assert kinds == ["round", "swing", "no swaps", "round"]
    older = summary("baoding", "allegro", "blind", "mix", 4, {"rotations_mean": 3.0})  # no net turns measured
    assert rows_of(task_table([*seeds, older], "baoding"))[("allegro", "blind")][8] == (
        "round 2, no swaps 1, not measured 1, swing 1"
    )
    assert "seeds by path" not in task_table([older], "baoding") and "by path" not in task_table(SUMMARIES, "bounce")


def baoding(variant, seed, rotations, net_turns):
    best = {"rotations_mean": rotations, "net_turns_mean": net_turns, "round_rotations_mean": min(rotations, net_turns)}
    return summary("baoding", "shadow", "blind", variant, seed, best, agent={"label": f"cfg_{variant}"})


VARIANT_SUMMARIES = [
    *[baoding("base", s, r, n) for s, r, n in ((0, 3.0, 0.5), (1, 10.0, 11.0), (2, 12.0, 12.5), (3, 14.0, 14.5))],
    *[baoding("bank", s, r, r + 0.5) for s, r in ((0, 9.0), (1, 11.0), (2, 13.0), (3, 13.0), (7, 8.0))],
    baoding("other_seeds", 9, 5.0, 5.0),
]


def test_the_variants_table_sets_each_variant_beside_the_baseline_seed_by_seed():
    from roto.olympiad.reference_tables import variants_table

    lines = variants_table(VARIANT_SUMMARIES, "base").splitlines()
    assert lines[0].startswith("| task | hand | obs | variant | agent config | seeds | mean ± std | per seed |")
    assert "seeds shared with base | paired difference [95 % CI] | seeds better / worse |" in lines[0]
    rows = [[cell.strip() for cell in line.strip("|").split(" | ")] for line in lines[2:]]
    assert [row[3] for row in rows] == ["base", "bank", "other_seeds"]  # the baseline first
    base, bank, other = rows
    # seed 0 of the baseline swings: 0.5 round rotations
    assert base[5:] == ["0, 1, 2, 3", "9.1 ± 5.2", "0.5, 10.0, 12.0, 14.0", "round 3, swing 1", "(baseline)", "", ""]
    assert bank[4:9] == ["`cfg_bank`", "0, 1, 2, 3, 7", "10.8 ± 2.0", "9.0, 11.0, 13.0, 13.0, 8.0", "round 5"]
    # paired on seeds 0-3: +8.5, +1, +1, -1 -> mean +2.4; seed 7 has no pair
    assert bank[9] == "0, 1, 2, 3" and bank[10].startswith("+2.4 [") and bank[11] == "3 / 1"
    assert other[9:] == ["none", "", ""]


def test_a_hand_and_mode_with_the_baseline_alone_gets_no_rows():
    """A baseline folder holds more pairs than a study trained (the benchmark's): only pairs with a
    variant beside the baseline are listed."""
    from roto.olympiad.reference_tables import variants_table

    alone = {**baoding("base", 0, 4.0, 4.0), "robot": "orca"}
    lines = variants_table([*VARIANT_SUMMARIES, alone], "base").splitlines()
    assert [line.split(" | ")[1] for line in lines[2:]] == ["shadow"] * 3
    assert variants_table([alone], "base").splitlines()[2:] == []

import csv
import json

import pytest

from roto.cli import main

CELLS = [  # (task, robot, variant, seed, final metric, best metric)
    *[("bounce", "shadow", "ppo", s, m, m + 1) for s, m in enumerate([10.0, 20.0, 30.0, 100.0])],
    ("bounce", "shadow", "fd", 0, 25.0, 25.0),
    ("bounce", "shadow", "fd", 1, 35.0, 40.0),
    ("baoding", "allegro", "ppo", 0, 1.5, 2.0),
]


AGENTS = {"ppo": {"label": "roto's PPO", "roto_agent": "ppo"}, "fd": {"label": "a swept FD", "roto_agent": None}}


def write_summaries(folder):
    folder.mkdir()
    for task, robot, variant, seed, final, best in CELLS:
        metric = "bounces" if task == "bounce" else "rotations"
        curve = [{"update": u, "env_steps": 1000 * u, "train_wall_s": 2.0 * u, "return_mean": final * u,
                  f"{metric}_mean": final * u / 2} for u in (1, 2)]  # fmt: skip
        summary = {"task": task, "robot": robot, "obs": "blind", "variant": variant, "seed": seed, "plan": "toy",
                   "commit": "abc1234", "env_steps": 2000, "train_wall_s": 4.0, "evaluations": curve,
                   "final": {f"{metric}_mean": final}, "best": {f"{metric}_mean": best},
                   "agent": AGENTS[variant], "task_version": {"bounce": 0, "baoding": 1}[task]}  # fmt: skip
        if task == "baoding":  # a summary that keeps its training scalars (older ones do not)
            summary["training"] = [{"env_steps": 1000 * u, "ppo/action_std": 1.0 + u} for u in (1, 2)]
        (folder / f"{task}-{robot}-blind-{variant}-seed{seed}.json").write_text(json.dumps(summary))


def test_results_match_hand_computed_statistics(tmp_path, capsys):
    write_summaries(tmp_path / "summaries")
    out = tmp_path / "out"
    assert main(["results", str(tmp_path / "summaries"), "--out", str(out)]) == 0
    rows = {(r["task"], r["robot"], r["variant"]): r for r in csv.DictReader((out / "results_final.csv").open())}
    ppo = rows[("bounce", "shadow", "ppo")]
    # 10, 20, 30, 100: mean 40, population std sqrt((900 + 400 + 100 + 3600) / 4), IQM mean of 20 and 30
    assert float(ppo["mean"]) == 40.0 and float(ppo["std"]) == pytest.approx(1250**0.5)
    assert float(ppo["iqm"]) == 25.0 and int(ppo["n"]) == 4 and ppo["metric"] == "bounces"
    assert float(ppo["iqm_ci95_low"]) <= 25.0 <= float(ppo["iqm_ci95_high"])
    assert float(rows[("baoding", "allegro", "ppo")]["mean"]) == 1.5  # rotations, one seed
    best = {(r["task"], r["variant"]): r for r in csv.DictReader((out / "results_best.csv").open())}
    assert float(best[("bounce", "fd")]["mean"]) == 32.5
    md = (out / "results.md").read_text()
    assert "plan toy, commit abc1234" in md
    assert "| shadow | " in md and "40.0 ± 35.4 (IQM 25.0" in md and "| 27.9 |" in md  # scripted Bounce beside
    # every column names its agent; roto v1's figures only where the variant declares itself roto's agent
    assert "| bounce (v0) / blind / fd: a swept FD | bounce (v0) / blind / ppo: roto's PPO |" in md
    assert "| roto v1, Shadow, 200 M steps (5 seeds) | 5.1 (ppo) |  | 69.0 (ppo) |  |  |" in md
    assert "| reference controller (rotations, v1) | scripted Bounce (bounces, v0) |" in md
    # P(fd > ppo) on Shadow Bounce's best policies: 25 beats 11 and 21, 40 beats 11, 21 and 31: 5 of 8 pairs
    assert "bounce / shadow / blind: P(fd > ppo) = 0.62" in md
    assert (out / "curves_bounce_shadow.png").stat().st_size > 0 and (out / "curves_baoding_allegro.png").is_file()
    # the action std plotted only where summaries keep it
    assert (out / "action_std_baoding_allegro.png").stat().st_size > 0
    assert not (out / "action_std_bounce_shadow.png").exists()


def test_baoding_curves_plot_round_rotations_where_every_record_has_them():
    from roto.olympiad.results import curve_measure

    measured = {"blind / ppo": [[{"rotations_mean": 3.0, "round_rotations_mean": 0.2}] * 2]}
    assert curve_measure("baoding", measured) == "round_rotations"
    older = {**measured, "state / ppo": [[{"rotations_mean": 3.0}]]}  # a run before paths were measured
    assert curve_measure("baoding", older) == "rotations"
    assert curve_measure("bounce", {"blind / ppo": [[{"bounces_mean": 1.0}]]}) == "bounces"


def test_each_curve_title_names_only_its_own_runs_commits(tmp_path, monkeypatch):
    from roto.olympiad import results

    write_summaries(tmp_path / "summaries")
    late = tmp_path / "summaries" / "baoding-allegro-blind-ppo-seed0.json"
    late.write_text(json.dumps({**json.loads(late.read_text()), "commit": "def5678"}))
    titles = {}
    monkeypatch.setattr(results, "plot_variants", lambda c, m, path, title, **kw: titles.setdefault(path.name, title))
    results.plot_curves(results.read_summaries(tmp_path / "summaries"), tmp_path, "benchmark")
    assert titles["curves_bounce_shadow.png"] == "bounce / shadow (plan benchmark, commit abc1234)"
    assert titles["curves_baoding_allegro.png"] == "baoding / allegro (plan benchmark, commit def5678)"
    assert titles["action_std_baoding_allegro.png"] == titles["curves_baoding_allegro.png"]


def test_one_seed_gets_no_spread_and_no_probability_of_improvement(tmp_path):
    from roto.olympiad.results_page import write_results

    write_summaries(tmp_path / "summaries")
    one = json.loads((tmp_path / "summaries" / "baoding-allegro-blind-ppo-seed0.json").read_text())
    one.update(variant="fd", agent=AGENTS["fd"], final={"rotations_mean": 3.0}, best={"rotations_mean": 3.0})
    (tmp_path / "summaries" / "baoding-allegro-blind-fd-seed0.json").write_text(json.dumps(one))
    write_results(tmp_path / "summaries", tmp_path / "out")
    md = (tmp_path / "out" / "results.md").read_text()
    assert "| 3.0 (n=1) |" in md and "| 1.5 (n=1) |" in md and "IQM 1.5" not in md
    assert "baoding / allegro" not in md.split("## Probability of improvement")[1]  # one seed each
    assert "bounce / shadow / blind: P(fd > ppo) = 0.62" in md  # two seeds against four: still a probability


def test_results_of_a_folder_without_summaries_is_a_clear_error(tmp_path, capsys):
    assert main(["results", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert "no cell summaries" in capsys.readouterr().err


def test_results_of_a_source_that_is_neither_a_folder_nor_a_plan_says_both(tmp_path, capsys):
    missing = tmp_path / "sumaries"  # a mistyped folder reads as a plan name
    assert main(["results", str(missing), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"SOURCE '{missing}' is neither a folder of cell summaries nor a plan" in err and "'benchmark'" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("where", "said"), [("missing", "does not exist"), ("a_file.json", "is a file")])
def test_adopting_from_a_missing_folder_or_a_file_names_it_and_writes_nothing(tmp_path, capsys, where, said):
    (tmp_path / "a_file.json").write_text("{}")
    results = tmp_path / "results"
    argv = ["olympiad", "smoke", "--results", str(results), "--adopt", "smoke", str(tmp_path / where)]
    assert main(argv) == 2
    assert f"the folder of cell summaries '{tmp_path / where}' {said}" in capsys.readouterr().err
    assert not results.exists()


def test_summaries_of_an_older_or_unrecorded_task_version_get_no_reference_column(tmp_path):
    from roto.olympiad.results_page import write_results

    write_summaries(tmp_path / "summaries")
    old = tmp_path / "summaries" / "baoding-allegro-blind-ppo-seed0.json"
    summary = json.loads(old.read_text())
    del summary["task_version"]
    old.write_text(json.dumps(summary))
    write_results(tmp_path / "summaries", tmp_path / "out")
    md = (tmp_path / "out" / "results.md").read_text()
    assert "baoding (older or unrecorded version) / blind / ppo" in md and "bounce (v0) / blind / ppo" in md
    assert "reference controller" not in md and "scripted Bounce (bounces, v0)" in md


def test_no_roto_v1_row_where_no_column_is_roto_agent():
    import numpy as np

    from roto.olympiad.results import markdown_table

    scores = {("baoding", "shadow", "blind", "recipe"): np.array([10.0])}
    plain = markdown_table(scores, {("baoding", "recipe"): {"label": "baoding_cpu + aids"}}, {"baoding"})
    assert "roto v1" not in plain and "| shadow | 10.0 (n=1) |" in plain
    roto = markdown_table(scores, {("baoding", "recipe"): {"label": "roto's", "roto_agent": "ppo"}}, {"baoding"})
    assert "| roto v1, Shadow, 200 M steps (5 seeds) | 5.1 (ppo) |  |" in roto


def test_path_metrics_stand_beside_the_headline_metric_and_older_summaries_say_not_measured(tmp_path):
    from roto.olympiad.results_page import write_results

    write_summaries(tmp_path / "summaries")
    newer = json.loads((tmp_path / "summaries" / "baoding-allegro-blind-ppo-seed0.json").read_text())
    newer["seed"] = 1
    newer["best"].update({"net_turns_mean": 0.25, "travelled_turns_mean": 14.62, "round_rotations_mean": 0.24})
    (tmp_path / "summaries" / "baoding-allegro-blind-ppo-seed1.json").write_text(json.dumps(newer))
    write_results(tmp_path / "summaries", tmp_path / "out")
    md = (tmp_path / "out" / "results.md").read_text()
    assert "| cell | rotations (best.pt) | net_turns | travelled_turns | round_rotations |" in md
    assert "| allegro / blind / ppo / seed 0 | 2.00 | not measured | not measured | not measured |" in md
    assert "| allegro / blind / ppo / seed 1 | 2.00 | 0.25 | 14.62 | 0.24 |" in md
    assert md.count("path metrics") == 1  # a table for Baoding, none for Bounce


def test_a_summary_without_round_rotations_gets_them_from_its_stored_episodes(tmp_path):
    from roto.olympiad.results_page import write_results

    write_summaries(tmp_path / "summaries")
    older = tmp_path / "summaries" / "baoding-allegro-blind-ppo-seed0.json"
    summary = json.loads(older.read_text())
    # written before round_rotations existed: per episode min(rotations, net turns) = 0.25 and 1.0
    summary["best"].update(
        {
            "net_turns_mean": 1.125,
            "travelled_turns_mean": 3.0,
            "per_episode": {"rotations": [3.0, 1.0], "net_turns": [0.25, 2.0], "travelled_turns": [3.0, 3.0]},
        }
    )
    older.write_text(json.dumps(summary))
    write_results(tmp_path / "summaries", tmp_path / "out")
    md = (tmp_path / "out" / "results.md").read_text()
    assert "| allegro / blind / ppo / seed 0 | 2.00 | 1.12 | 3.00 | 0.62 |" in md


def test_derived_means_leave_a_measured_value_and_an_evaluation_without_episodes_as_they_are():
    from roto.olympiad.path_results import with_derived_means

    measured = {"round_rotations_mean": 0.5, "per_episode": {"rotations": [3.0], "net_turns": [0.25]}}
    assert with_derived_means("baoding", measured)["round_rotations_mean"] == 0.5
    assert with_derived_means("baoding", {"rotations_mean": 2.0}) == {"rotations_mean": 2.0}
    bounce = {"per_episode": {"bounces": [60.0, 62.0]}}
    assert with_derived_means("bounce", bounce) == bounce


def test_baoding_results_lead_with_round_rotations_where_every_seed_measured_them(tmp_path):
    from roto.olympiad.results_page import write_results

    write_summaries(tmp_path / "summaries")

    def md_of():
        write_results(tmp_path / "summaries", tmp_path / "out")
        return (tmp_path / "out" / "results.md").read_text()

    md = md_of()  # the one Baoding seed predates path metrics: its cell is listed as not measured
    lead = md.index("## best policy: baoding: round_rotations (roto's rotations in the tables below)")
    assert lead < md.index("## final policy") and "Not measured (summaries written before" in md
    assert "baoding / allegro / blind / ppo" in md[lead : md.index("## final policy")]
    path = tmp_path / "summaries" / "baoding-allegro-blind-ppo-seed0.json"
    summary = json.loads(path.read_text())
    summary["best"].update({"net_turns_mean": 0.3, "round_rotations_mean": 0.25})  # swung: 2 by roto's count
    path.write_text(json.dumps(summary))
    md = md_of()
    section = md[md.index("## best policy: baoding") : md.index("## final policy")]
    assert "| allegro | 0.2 (n=1) |" in section and "Not measured" not in section
    assert "| allegro | 2.0 (n=1) |" in md[md.index("## best policy: the task's") :]  # roto's count stays below


def test_probabilities_of_improvement_compare_round_rotations_not_roto_count():
    """A variant that swings the balls out and back scores more swaps than one that goes round: the
    probability of improvement, like the tables it follows, ranks the best policies' round rotations."""
    from roto.olympiad.results_page import results_markdown

    summaries = []
    for variant, rotations, round_rotations in (("swing", 14.0, 0.25), ("round", 11.0, 11.0)):
        for seed in (0, 1):
            best = {"rotations_mean": rotations + seed, "round_rotations_mean": round_rotations + seed}
            summaries.append({"task": "baoding", "robot": "shadow", "obs": "blind", "variant": variant, "seed": seed,
                              "plan": "toy", "commit": "abc1234", "env_steps": 2000, "evaluations": [],
                              "final": {"rotations_mean": rotations + seed}, "best": best,
                              "task_version": 1})  # fmt: skip
    md = results_markdown(summaries)
    section = md[md.index("## Probability of improvement (best policies, lead measure;") :]
    assert "baoding / shadow / blind: P(round > swing) = 1.00" in section


def test_a_page_label_counts_the_commits_beyond_three():
    from roto.olympiad.results import page_label

    summaries = [{"plan": "toy", "commit": c} for c in ("a1", "b2", "c3")]
    assert page_label(summaries) == "plan toy, commit a1, b2, c3"
    summaries.append({"plan": "toy", "commit": "d4", "trained_by": [{"commit": "e5", "from_env_steps": 0}]})
    assert page_label(summaries, "benchmark") == "plan benchmark, 5 commits, each cell's in manifest.csv"

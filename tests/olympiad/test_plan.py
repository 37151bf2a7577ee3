import dataclasses
import json
import math
import pathlib

import pytest

from roto.envs.replay_starts import packaged_banks
from roto.olympiad.plan import Cell, load_plan, packaged_plans, select_cells
from roto.rl.config_files import load_agent_config
from roto.robots import ROBOTS

ROOT = pathlib.Path(__file__).resolve().parents[2]


EARLIER_CONFIGS = ROOT / "experiments" / "baoding_configs"
"""The earlier per-hand Baoding agent configs (not plans), kept for the experiments that trained them."""
EXPERIMENT_PLANS = {
    path.stem: path for path in (ROOT / "experiments").glob("*/*.yaml") if path.parent != EARLIER_CONFIGS
}
"""The plans roto's experiments ran (experiments/<study>/<plan>.yaml), by name."""


def earlier(hand: str) -> str:
    """The path of the earlier Baoding config ``baoding_cpu_<hand>`` (``orca_round``: ORCA's round one)."""
    return str(EARLIER_CONFIGS / f"baoding_cpu_{hand}.yaml")


TURN_SHAPING = {"per_turn": 20, "lead": None, "near": None, "soft": False, "near_from": None, "near_turns": 3.0}
"""baoding_cpu's turn shaping, every setting."""


def plan_named(name: str):
    """A packaged plan, or an experiment's by its file's name."""
    return load_plan(str(EXPERIMENT_PLANS[name]) if name in EXPERIMENT_PLANS else name)


@pytest.mark.parametrize("name", sorted(EXPERIMENT_PLANS))
def test_every_experiments_plan_still_passes_the_plan_check(name):
    """An experiment's command still runs: its configs, banks and overrides load with today's roto."""
    assert plan_named(name).cells


def test_packaged_plans():
    assert set(packaged_plans()) == {"benchmark", "paper", "smoke"}
    smoke = load_plan("smoke")
    assert [c.name for c in smoke.cells] == ["bounce-shadow-blind-ppo-seed0", "baoding-shadow-blind-ppo-seed0"]
    cpu = plan_named("cpu")
    names = [c.name for c in cpu.cells]
    assert len(names) == 28 and cpu.steps == 5_000_000 and cpu.eval_episodes == 100
    assert sum(n.startswith("bounce-") and "-blind-" in n for n in names) == 8  # 4 hands x 2 seeds
    assert sum(n.startswith("baoding-") for n in names) == 4  # 4 hands x 1 seed
    assert {n for n in names if "-blind-" not in n} == {
        f"bounce-{robot}-{obs}-ppo-seed{s}"
        for robot in ("shadow", "shadow_lite", "allegro", "orca")
        for obs in ("state", "proprio")
        for s in (0, 1)
    }
    assert [c.seed for c in cpu.cells] == sorted(c.seed for c in cpu.cells)  # every first seed before a second
    recipes = {robot: cpu.variants["ppo"].agent_for("bounce", robot)[0] for robot in ROBOTS}  # each hand's record's
    quickstart = {robot: "bounce_cpu_quickstart" for robot in ("shadow", "shadow_lite", "allegro")}
    assert recipes == {**quickstart, "orca": "bounce_cpu_orca"}
    shadow, orca = (load_agent_config("bounce", recipes[r]) for r in ("shadow", "orca"))
    assert orca.ppo.lr != shadow.ppo.lr
    long = plan_named("bounce_long_shadow")
    assert [c.name for c in long.cells] == [f"bounce-shadow-blind-quickstart-seed{s}" for s in (0, 1)]
    assert long.steps == 20_000_000 and long.variants["quickstart"].agent_for("bounce") == ("bounce_cpu_quickstart", [])
    paper = load_plan("paper")
    assert len(paper.cells) == 4 * 2 * 2 * 5 and paper.steps == 200_000_000 and paper.backend == "warp"


GRID = "grids:\n  - {tasks: [bounce], robots: [shadow], obs: [blind], variants: [ppo], seeds: [0]}\n"
VARIANTS = "variants:\n  ppo:\n    bounce: {agent_cfg: bounce_cpu_quickstart}\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (VARIANTS + GRID.replace("[shadow]", "[shadow, r2d2]"), r"unknown robot 'r2d2'; valid robots: \['allegro'"),
        (VARIANTS + GRID.replace("[bounce]", "[juggle]"), r"unknown task 'juggle'; valid tasks: \['baoding'"),
        (VARIANTS + GRID.replace("[blind]", "[xray]"), r"unknown obs mode 'xray'; valid obs: \['blind'"),
        (VARIANTS + GRID.replace("[ppo]", "[sac]"), r"unknown variant 'sac'; valid variants: \['ppo'\]"),
        (VARIANTS + GRID.replace("[0]", "[-1]"), r"seeds must be integers >= 0, got -1"),
        (VARIANTS + GRID + "stepz: 10\n", r"unknown keys \['stepz'\]; valid keys: \["),
        (VARIANTS + GRID + "backend: physx\n", r"unknown backend 'physx'; valid backends: \['cpu', 'warp'\]"),
        (VARIANTS.replace("bounce:", "baoding:") + GRID, r"variant 'ppo' has no config for task 'bounce'"),
        (VARIANTS.replace("quickstart}", "quickstart, overrides: [ppo.lrr=1]}") + GRID, r"key 'ppo.lrr'"),
        (VARIANTS.replace("bounce_cpu_quickstart", "bounce_fd") + GRID, r"packaged config: \['baoding'"),
        (VARIANTS, r"has no cells"),
        (VARIANTS.replace("quickstart}", "quickstart, overrides: [env.task=x]}") + GRID, r"unknown env key 'task'"),
        (VARIANTS.replace("quickstart}", "quickstart, overrides: [env.touch=smell]}") + GRID, r"smell"),
        (VARIANTS.replace("quickstart}", "quickstart, roto_agent: sac}") + GRID, r"unknown roto_agent 'sac'"),
    ],
)  # fmt: skip
def test_a_bad_plan_is_rejected_naming_the_valid_choices(tmp_path, text, message):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises((ValueError, FileNotFoundError), match=message):
        load_plan(str(path))


def test_cli_rejects_a_bad_plan_before_anything_runs(tmp_path, capsys):
    from roto.cli import main

    path = tmp_path / "bad.yaml"
    path.write_text(VARIANTS + GRID.replace("[shadow]", "[r2d2]"))
    assert main(["olympiad", str(path), "--root", str(tmp_path / "runs")]) == 2
    assert "unknown robot 'r2d2'" in capsys.readouterr().err
    assert not (tmp_path / "runs").exists()
    assert main(["olympiad", "nope"]) == 2
    assert f"packaged plan: {sorted(packaged_plans())}" in capsys.readouterr().err


def test_dry_run_lists_cells_and_estimates_the_time_left_from_finished_cells(tmp_path, capsys):

    from roto.cli import main

    results = tmp_path / "results"
    results.mkdir()
    committed = ROOT / "benchmarks" / "results" / "benchmark" / "cells" / "bounce-shadow-blind-ppo-seed0.json"
    done = {**json.loads(committed.read_text()), "env_steps": 5_000_000, "train_wall_s": 1000.0}  # 5000 env steps/s
    (results / "bounce-shadow-blind-ppo-seed0.json").write_text(json.dumps(done))
    assert main(["olympiad", "benchmark", "--dry-run", "--root", str(tmp_path), "--results", str(results)]) == 0
    out = capsys.readouterr().out
    assert "bounce-shadow-blind-ppo-seed0" in out and out.count(" done [5 M]\n") == 1
    # 79 cells left: 34 of Bounce and 11 of Shadow Baoding at 5 M, 33 of the other hands' Baoding
    # at 10 M: 560 M steps at 5000 env steps/s = 112000 s
    assert "1 done, 79 left; time left: 31.1 h for one worker at bounce 5000, baoding 5000 env steps/s" in out
    assert "(the finished cells' throughput per task; baoding at all the finished cells' throughput)" in out
    assert (
        f"no workers' journal at {tmp_path / 'benchmark' / 'journal.log'}: a cell running under another --root" in out
    )
    assert not (tmp_path / "benchmark").exists()  # a dry run creates no study
    started = tmp_path / "benchmark" / "bounce-allegro-blind-ppo-seed0"  # a cell's run, 2.5 M steps in
    started.mkdir(parents=True)
    rounds = [{"update": 305, "env_steps": 1_250_000, "bounces_mean": 31.5},
              {"update": 610, "env_steps": 2_500_000, "bounces_mean": 27.25}]  # fmt: skip
    (started / "evaluations.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rounds))
    assert main(["olympiad", "benchmark", "--dry-run", "--root", str(tmp_path), "--results", str(results)]) == 0
    out = capsys.readouterr().out
    assert "bounce-allegro-blind-ppo-seed0" in out
    assert "(2.5 M env steps; last evaluation 27.25 bounces, best 31.50 at 1.2 M)" in out
    assert "time left: 31.0 h for one worker" in out  # (560 M - 2.5 M) / 5000 env steps/s = 111500 s
    assert main(["olympiad", "benchmark", "--dry-run", "--workers", "2", "--root", str(tmp_path), "--results",
                 str(results)]) == 0  # fmt: skip
    # largest first over two workers: the 10 M cells 170 M and 160 M, the 5 M ones 110 M and 115 M,
    # the 2.5 M one to the second: 280 M on the busier one = 56000 s
    assert "with 2 workers: 15.6 h" in capsys.readouterr().out
    baoding = ROOT / "benchmarks" / "results" / "benchmark" / "cells" / "baoding-shadow-blind-ppo-seed0.json"
    slower = {**json.loads(baoding.read_text()), "env_steps": 5_000_000, "train_wall_s": 2000.0}  # 2500 env steps/s
    (results / baoding.name).write_text(json.dumps(slower))
    (results / "baoding-shadow-blind-other-seed0.json").write_text(json.dumps({**slower, "variant": "other"}))
    assert main(["olympiad", "benchmark", "--dry-run", "--workers", "2", "--root", str(tmp_path), "--results",
                 str(results)]) == 0  # fmt: skip
    out = capsys.readouterr().out  # each task at its own cells' rate; another plan's summary is not counted
    # Bounce 172.5 M at 5000 env steps/s (34500 s), Baoding 380 M at 2500 (152000 s): 186500 s
    assert "2 done, 78 left; time left: 51.8 h for one worker at bounce 5000, baoding 2500 env steps/s" in out
    assert "(the finished cells' throughput per task)" in out
    # two workers, largest first: the 10 M cells (4000 s) 17 and 16, the Shadow's (2000 s) 4 and 6,
    # Bounce (1000 s) 17 and 17, the started one (500 s) to the first: 93500 s on the busier one
    assert "with 2 workers: 26.0 h" in out
    assert sorted(p.name for p in (tmp_path / "benchmark").iterdir()) == [started.name]  # still no study
    none = ["--results", str(tmp_path / "none")]
    assert main(["olympiad", "benchmark", "--dry-run", "--root", str(tmp_path), *none]) == 0
    assert f"time left: unknown: no finished cell's summary in {tmp_path / 'none'}" in capsys.readouterr().out
    timed = [{**r, "train_wall_s": r["env_steps"] / 2500} for r in rounds]  # 2500 env steps/s between its rounds
    (started / "evaluations.jsonl").write_text("".join(json.dumps(r) + "\n" for r in timed))
    assert main(["olympiad", "benchmark", "--dry-run", "--root", str(tmp_path), *none]) == 0
    # no finished cell: the started cell's throughput, (565 M - 2.5 M) / 2500 env steps/s = 225000 s
    assert "time left: 62.5 h for one worker at bounce 2500, baoding 2500 env steps/s (the started cells' last" in (
        capsys.readouterr().out
    )
    assert main(["olympiad", "benchmark", "--dry-run", "--workers", "2", "--root", str(tmp_path), "--results",
                 str(tmp_path / "none")]) == 0  # fmt: skip
    # the 10 M cells 170 M and 160 M, the 46 of 5 M 110 M and 120 M, the 2.5 M one: 282.5 M = 113000 s
    assert "with 2 workers: 31.4 h" in (capsys.readouterr().out)


def test_only_keeps_the_cells_a_pattern_matches_in_the_plans_order_and_refuses_one_that_matches_none():
    plan = load_plan("benchmark")
    assert select_cells(plan, ()) is plan
    bounce = select_cells(plan, ["bounce-*"])
    assert bounce.name == plan.name and bounce.steps_for(bounce.cells[0]) == plan.steps_for(bounce.cells[0])
    assert bounce.cells == tuple(c for c in plan.cells if c.task == "bounce") and len(bounce.cells) == 36
    picked = select_cells(plan, ["*-state-*-seed2", "baoding-allegro-blind-*"])
    expected = [c for c in plan.cells if (c.obs == "state" and c.seed == 2) or (c.task, c.robot, c.obs) == (
        "baoding", "allegro", "blind")]  # fmt: skip
    assert list(picked.cells) == expected and len(expected) == 8 + 5
    message = r"--only 'bounce-r2d2-\*' matches none of the 80 cells of plan 'benchmark'; .*e\.g\. bounce-shadow-blind"
    with pytest.raises(ValueError, match=message):
        select_cells(plan, ["bounce-*", "bounce-r2d2-*"])


def test_cli_only_lists_the_chosen_cells_and_refuses_a_pattern_that_matches_none_before_anything_runs(tmp_path, capsys):
    from roto.cli import main

    root, results = tmp_path / "runs", tmp_path / "results"
    argv = ["olympiad", "benchmark", "--dry-run", "--root", str(root), "--results", str(results)]
    assert main([*argv, "--only", "*-orca-state-*"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("plan benchmark: 6 cells of its 80 (--only), env steps per cell as listed")
    assert out.count("-orca-state-ppo-seed") == 6
    assert "bounce-shadow" not in out and "6 left" in out
    committed = ROOT / "benchmarks" / "results" / "benchmark" / "cells" / "bounce-shadow-blind-ppo-seed0.json"
    results.mkdir()
    done = {**json.loads(committed.read_text()), "env_steps": 5_000_000, "train_wall_s": 1000.0}  # 5000 env steps/s
    (results / committed.name).write_text(json.dumps(done))
    assert main([*argv, "--only", "bounce-orca-state-*"]) == 0  # a cell --only left out sets the pace
    out = capsys.readouterr().out  # 3 cells of 5 M at 5000 env steps/s = 3000 s
    assert "0 done, 3 left; time left: 0.8 h for one worker at bounce 5000 env steps/s" in out
    assert (
        main(["olympiad", "benchmark", "--root", str(root), "--results", str(results), "--only", "baoding-ghost*"]) == 2
    )
    assert "--only 'baoding-ghost*' matches none of the 80 cells of plan 'benchmark'" in capsys.readouterr().err
    assert not root.exists() and sorted(p.name for p in results.iterdir()) == [committed.name]


def test_variant_plans_carry_env_overrides_into_their_cells_and_name_their_agents():
    from roto.olympiad.cell import cell_spec

    plan = plan_named("variants_bounce")
    force = cell_spec(plan, Cell("bounce", "shadow", "blind", "force_touch", 1))
    binary = cell_spec(plan, Cell("bounce", "shadow", "blind", "ppo", 1))
    assert force.env.touch == "force" and binary.env.touch == "binary" and force.env.seed == 1
    assert force.agent == binary.agent and force.agent.ppo.entropy_coef == 0.004
    assert (
        plan.variants["force_touch"].for_task("bounce").label == "bounce_cpu + ppo.entropy_coef=0.004, env.touch=force"
    )
    assert load_plan("paper").variants["ppo"].for_task("bounce").roto_agent == "ppo"
    assert plan_named("cpu").variants["ppo"].for_task("bounce").roto_agent is None  # the swept critic is not roto's PPO


def test_robot_in_an_override_becomes_each_cells_hand():
    from roto.olympiad.cell import cell_spec

    plan = plan_named("baoding_v1_cpu")
    cells = (("shadow", "task_critic_replay", 0.25), ("orca", "task_critic_more_aids_low_noise", 0.5))
    for robot, variant, share in cells:
        spec = cell_spec(plan, Cell("baoding", robot, "blind", variant, 1))
        assert spec.env.aids.replayed_starts.bank == f"{robot}_preswap"
        assert spec.env.aids.replayed_starts.share == share and spec.agent.ppo.epochs == 4 and spec.env.threads == 1
    assert {(c.robot, c.variant) for c in plan.cells} == {
        ("shadow", "task_critic_replay"),
        *((robot, "task_critic_more_aids") for robot in ("shadow_lite", "allegro")),
        ("orca", "task_critic_more_aids_low_noise"),
    }
    lite = cell_spec(plan, Cell("baoding", "shadow_lite", "blind", "task_critic_more_aids", 0))
    more_aids = plan_named("baoding_v1_more_aids")
    same = cell_spec(more_aids, next(c for c in more_aids.cells if c.variant == "all_three"))
    assert lite.differences(same) == {}  # the all_three run continues as this plan's cell
    assert all(f"{c.robot}_preswap" in packaged_banks() for c in plan.cells)


def test_robot_in_an_agent_config_names_a_config_per_hand_and_a_missing_one_is_refused(tmp_path):
    from roto.olympiad.cell import cell_spec

    for robot, lr in (("shadow", 1.0e-4), ("allegro", 3.0e-4)):
        (tmp_path / f"tuned_{robot}.yaml").write_text(f"extends: bounce_cpu_quickstart\nppo:\n  lr: {lr}\n")
    plan_text = """steps: 1000
variants:
  tuned:
    bounce: {agent_cfg: "%s/tuned_{robot}.yaml"}
grids:
  - {tasks: [bounce], robots: [%s], obs: [blind], variants: [tuned], seeds: [0]}
"""
    plan_file = tmp_path / "plan.yaml"
    plan_file.write_text(plan_text % (tmp_path, "shadow, allegro"))
    plan = load_plan(str(plan_file))
    specs = {robot: cell_spec(plan, Cell("bounce", robot, "blind", "tuned", 0)) for robot in ("shadow", "allegro")}
    assert specs["shadow"].agent.ppo.lr == 1.0e-4 and specs["allegro"].agent.ppo.lr == 3.0e-4
    plan_file.write_text(plan_text % (tmp_path, "shadow, orca"))
    with pytest.raises(ValueError, match=r"variant 'tuned' on bounce/orca/blind: .*tuned_orca.yaml"):
        load_plan(str(plan_file))


def test_the_more_aids_plan_adds_each_aid_to_the_recipe_for_shadow_lite():
    from roto.olympiad.cell import cell_spec

    plan = plan_named("baoding_v1_more_aids")
    specs = {c.variant: cell_spec(plan, c) for c in plan.cells if c.robot == "shadow_lite"}
    assert len(specs) == 4
    assert all(
        s.env.aids.replayed_starts.bank == "shadow_lite_preswap" and s.agent.ppo.epochs == 4 for s in specs.values()
    )
    tolerance, record = specs["tolerance"].env.aids, specs["record"].env.aids
    assert tolerance.tolerance.start == 0.025 and tolerance.replayed_starts.record_lead == 0
    assert record.replayed_starts.record_lead == 10 and record.tolerance is None
    assert specs["share_half"].env.aids.replayed_starts.share == 0.5
    everything = specs["all_three"].env.aids
    assert (everything.replayed_starts.share, everything.tolerance.start, everything.replayed_starts.record_lead) == (
        0.5,
        0.025,
        10,
    )


@pytest.mark.parametrize(
    ("robot", "probe_variant", "cell_variant"),
    [
        ("allegro", "all_three", "task_critic_more_aids"),
        ("orca", "all_three_low_noise", "task_critic_more_aids_low_noise"),
    ],
)
def test_the_more_aids_probe_of_a_hand_trains_as_its_20m_cell_does(robot, probe_variant, cell_variant):
    """The 5 M probe's run continues as the baoding_v1_cpu cell: nothing but the budget differs."""
    from roto.olympiad.cell import cell_spec

    probe = cell_spec(plan_named("baoding_v1_more_aids"), Cell("baoding", robot, "blind", probe_variant, 0))
    cell = cell_spec(plan_named("baoding_v1_cpu"), Cell("baoding", robot, "blind", cell_variant, 0))
    assert probe.differences(cell) == {} and probe.env.aids.replayed_starts.bank == f"{robot}_preswap"
    assert (probe.steps, cell.steps) == (5_000_000, 20_000_000)


def test_the_low_noise_variant_differs_from_all_three_only_in_the_policy_std():
    from roto.olympiad.cell import cell_spec

    plan = plan_named("baoding_v1_more_aids")
    low = cell_spec(plan, Cell("baoding", "orca", "blind", "all_three_low_noise", 0))
    usual = cell_spec(plan, Cell("baoding", "orca", "blind", "all_three", 0))
    assert low.differences(usual) == {
        "agent.network.init_log_std": (-1.386, 0.0),
        "agent.network.max_log_std": (-1.386, 2.0),
    }


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_every_hands_baoding_record_names_baoding_cpu_whose_only_hand_part_is_the_hands_own_bank(robot):
    """One Baoding recipe for every hand: the record of each pair names ``baoding_cpu``, and a hand's
    run differs from the Shadow's only in the hand and the bank of its own round reference controller."""
    from roto.rl.run_spec import build_run_spec

    def blind(hand):
        return build_run_spec("baoding", hand, "blind", ROBOTS[hand].tasks["baoding"].recipe, [], num_envs=128)

    assert ROBOTS[robot].tasks["baoding"].recipe == "baoding_cpu"
    expected = (
        {}
        if robot == "shadow"
        else {
            "env.robot": (robot, "shadow"),
            "env.aids.replayed_starts.bank": (f"{robot}_round_preswap", "shadow_round_preswap"),
        }
    )
    assert blind(robot).differences(blind("shadow")) == expected


def test_the_shadows_more_aids_cell_is_the_other_hands_recipe_and_adds_two_aids_to_its_own():
    """The Shadow's three-aid cell joins baoding_v1_cpu's column; it differs from its one-aid cell in the aids only."""
    from roto.olympiad.cell import cell_spec

    plan, main = plan_named("baoding_v1_shadow_more_aids"), plan_named("baoding_v1_cpu")
    assert [c.name for c in plan.cells] == [f"baoding-shadow-blind-task_critic_more_aids-seed{s}" for s in (0, 1)]
    variant = "task_critic_more_aids"
    assert plan.variants[variant] == main.variants[variant] and (plan.steps, plan.threads) == (main.steps, main.threads)
    three = cell_spec(plan, Cell("baoding", "shadow", "blind", variant, 1))
    one = cell_spec(main, Cell("baoding", "shadow", "blind", "task_critic_replay", 1))
    assert three.differences(one) == {
        "env.aids.replayed_starts.share": (0.5, 0.25),
        "env.aids.replayed_starts.record_lead": (10, 0),
        "env.aids.tolerance": ({"start": 0.025, "target": 2, "by": "headline", "deadline": None}, None),
    }


def test_each_ablation_changes_exactly_its_part_of_the_baoding_recipe():
    """The ablations' recipe is the Olympiad's Baoding recipe; every other cell differs from it in one part only."""
    from roto.olympiad.cell import cell_spec

    plan, main = plan_named("baoding_v1_ablations"), plan_named("baoding_v1_cpu")
    assert {c.seed for c in plan.cells} == {1} and {c.robot for c in plan.cells} == {"shadow"}
    recipe = cell_spec(plan, Cell("baoding", "shadow", "blind", "recipe", 1))
    assert recipe.differences(cell_spec(main, Cell("baoding", "shadow", "blind", "task_critic_more_aids", 1))) == {}
    bank = "shadow_preswap"
    replayed = {"bank": bank, "share": 0.5, "record_lead": 10, "record_capacity": 1024}
    tolerance = {"start": 0.025, "target": 2, "by": "headline", "deadline": None}
    expected = {
        "recipe": {},
        "no_replay": {"env.aids.replayed_starts": (None, replayed)},
        "no_own_swaps": {"env.aids.replayed_starts.record_lead": (0, 10)},
        "no_tolerance": {"env.aids.tolerance": (None, tolerance)},
        "plain_critic": {"agent.network.critic": (None, ["tactile", "proprio", "privileged", "task"])},
        "roto_epochs": {"agent.ppo.epochs": (8, 4)},
        "std_bound": {"agent.network.max_log_std": (0.0, 2.0)},
        "std_bound_projected": {"agent.network.max_log_std": (0.0, 2.0),
                                "agent.network.project_log_std": (True, False)},
        "low_noise": {"agent.network.init_log_std": (-1.386, 0.0), "agent.network.max_log_std": (-1.386, 2.0)},
    }  # fmt: skip
    assert [c.variant for c in plan.cells] == list(expected)
    for variant, changes in expected.items():
        assert cell_spec(plan, Cell("baoding", "shadow", "blind", variant, 1)).differences(recipe) == changes, variant


def test_the_low_noise_plan_trains_orcas_recipe_on_other_hands_as_the_ablation_did_on_the_shadow():
    """Each cell is ORCA's Olympiad recipe on its hand at 5 M; the Shadow's seed 1 is the ablation's low_noise cell."""
    from roto.olympiad.cell import cell_spec

    plan, main, ablations = (plan_named(n) for n in ("baoding_v1_low_noise", "baoding_v1_cpu", "baoding_v1_ablations"))
    variant = "task_critic_more_aids_low_noise"
    assert plan.variants[variant] == main.variants[variant] and plan.steps == ablations.steps == 5_000_000
    cells = [(c.robot, c.seed) for c in plan.cells]
    assert cells == [("shadow", 0), ("shadow_lite", 0), ("shadow_lite", 1), ("orca", 1)]
    shadow = cell_spec(plan, Cell("baoding", "shadow", "blind", variant, 1))  # seed 1 as the ablation ran it
    assert shadow.differences(cell_spec(ablations, Cell("baoding", "shadow", "blind", "low_noise", 1))) == {}
    for cell in plan.cells:
        spec = cell_spec(plan, cell)
        assert (
            spec.env.aids.replayed_starts.bank == f"{cell.robot}_preswap" and spec.agent.network.max_log_std == -1.386
        )


def test_the_cycle_variant_differs_from_the_low_noise_one_only_in_its_bank_of_starts():
    from roto.olympiad.cell import cell_spec

    plan = plan_named("baoding_v1_more_aids")
    cycle = cell_spec(plan, Cell("baoding", "allegro", "blind", "cycle_low_noise", 0))
    low = cell_spec(plan, Cell("baoding", "allegro", "blind", "all_three_low_noise", 0))
    bank = "allegro_cycle"
    assert cycle.differences(low) == {"env.aids.replayed_starts.bank": (bank, bank.replace("cycle", "preswap"))}
    assert bank in packaged_banks()


def test_the_round_plan_changes_orcas_recipe_only_in_what_it_names():
    """Each cell is ORCA's earlier recipe with the round-swap aid, the round controller's bank, or both
    (on two seeds); the 20 M plan continues the cells with both, which ``baoding_cpu_orca_round`` is."""
    from roto.olympiad.cell import cell_spec
    from roto.rl.run_spec import build_run_spec

    plan = plan_named("baoding_v1_round")
    recipe = build_run_spec("baoding", "orca", "blind", earlier("orca"), [], plan.steps, num_envs=128, threads=1)
    bank, round_bank = (
        recipe.env.aids.replayed_starts.bank,
        "orca_round_preswap",
    )
    expected = {
        "round_swaps": {"env.aids.round_swaps": ({"min_turn": 0.25, "first_paid": False, "after": None}, None)},
        "round_bank": {"env.aids.replayed_starts.bank": (round_bank, bank)},
        "round_bank_round_swaps": {
            "env.aids.replayed_starts.bank": (round_bank, bank),
            "env.aids.round_swaps": ({"min_turn": 0.25, "first_paid": False, "after": None}, None),
        },
    }
    assert [(c.variant, c.seed) for c in plan.cells] == [
        ("round_swaps", 0),
        ("round_bank", 0),
        ("round_bank_round_swaps", 0),
        ("round_bank_round_swaps", 1),
    ]
    for cell in plan.cells:
        seed = {"env.seed": (cell.seed, 0)} if cell.seed else {}
        assert cell_spec(plan, cell).differences(recipe) == {**expected[cell.variant], **seed}
    assert round_bank in packaged_banks()
    long = plan_named("baoding_v1_orca_round")  # the round cells' continuation: the same runs, longer
    assert long.steps == 20_000_000
    assert [c.name for c in long.cells] == [c.name for c in plan.cells if c.variant == "round_bank_round_swaps"]
    for cell in long.cells:  # training the same (the budget aside), so each 5 M run continues
        assert cell_spec(long, cell).differences(cell_spec(plan, cell)) == {}
    packaged = build_run_spec(
        "baoding", "orca", "blind", earlier("orca_round"), [], plan.steps, num_envs=128, threads=1
    )
    assert packaged.differences(cell_spec(plan, Cell("baoding", "orca", "blind", "round_bank_round_swaps", 0))) == {}


def test_the_shadows_round_plan_is_its_recipe_with_the_round_bank_and_round_swaps_on_the_seed_it_swung():
    from roto.olympiad.cell import cell_spec
    from roto.rl.run_spec import build_run_spec

    plan = plan_named("baoding_v1_shadow_round")
    assert [c.name for c in plan.cells] == ["baoding-shadow-blind-round-seed3"] and plan.steps == 5_000_000
    recipe = build_run_spec("baoding", "shadow", "blind", earlier("shadow"), [], plan.steps, num_envs=128, threads=1)
    round_bank = "shadow_round_preswap"
    assert cell_spec(plan, plan.cells[0]).differences(recipe) == {
        "env.aids.replayed_starts.bank": (round_bank, recipe.env.aids.replayed_starts.bank),
        "env.aids.round_swaps": ({"min_turn": 0.25, "first_paid": False, "after": None}, None),
        "env.aids.turn_shaping": (None, TURN_SHAPING),  # the recipe's since it ran
        "env.seed": (3, 0),
    }  # fmt: skip
    assert round_bank in packaged_banks()


def test_the_dry_run_line_shows_the_last_evaluations_path_metrics_where_it_has_them():
    from roto.olympiad.command import headline_so_far

    turns = {"net_turns_mean": 0.25, "travelled_turns_mean": 3.5}
    rounds = [{"env_steps": 1_000_000, "rotations_mean": 6.0}, {"env_steps": 2_000_000, "rotations_mean": 5.5, **turns}]
    names = ("net_turns", "travelled_turns")
    line = headline_so_far(rounds, "rotations", names)
    assert line == "; last evaluation 5.50 rotations (net_turns 0.25, travelled_turns 3.50), best 6.00 at 1.0 M"
    assert headline_so_far(rounds[:1], "rotations", names) == "; last evaluation 6.00 rotations, best 6.00 at 1.0 M"
    from roto.olympiad.command import status_metrics
    from roto.tasks import get_task

    baoding = get_task("baoding")
    assert status_metrics(baoding, rounds) == ("rotations", ("net_turns", "travelled_turns", "round_rotations"))
    measured = [{**rounds[1], "round_rotations_mean": 0.25}]  # Baoding leads with round rotations where measured
    assert status_metrics(baoding, measured) == ("round_rotations", ("rotations", "net_turns", "travelled_turns"))
    assert headline_so_far(measured, *status_metrics(baoding, measured)).startswith(
        "; last evaluation 0.25 round_rotations (rotations 5.50, net_turns 0.25, travelled_turns 3.50)"
    )


def test_the_benchmark_plan_trains_every_hand_and_mode_with_its_record_s_recipe():
    """Bounce: every hand and mode on seeds 0-2 (the cpu plan's cells where it had them); Baoding:
    blind on seeds 0-4, state and proprio on 0-2, 5 M env steps on the Shadow and 10 M on the others."""
    from roto.olympiad.cell import cell_spec

    plan, cpu = load_plan("benchmark"), plan_named("cpu")
    modes = ("blind", "state", "proprio")
    assert {(c.robot, c.obs, c.seed) for c in plan.cells if c.task == "bounce"} == {
        (robot, obs, seed) for robot in ROBOTS for obs in modes for seed in (0, 1, 2)
    }
    baoding = {(c.robot, c.obs, c.seed): plan.steps_for(c) for c in plan.cells if c.task == "baoding"}
    assert baoding == {
        (robot, obs, seed): 5_000_000 if robot == "shadow" else 10_000_000
        for robot in ROBOTS
        for obs in modes
        for seed in ((0, 1, 2, 3, 4) if obs == "blind" else (0, 1, 2))
    }
    for cell in plan.cells:
        assert plan.variants["ppo"].agent_for(cell.task, cell.robot)[0] == ROBOTS[cell.robot].tasks[cell.task].recipe
    shared = [c for c in plan.cells if c in set(cpu.cells) and c.task == "bounce"]  # the cpu plan's, same names
    assert len(shared) == 24 and all(cell_spec(plan, c).differences(cell_spec(cpu, c)) == {} for c in shared)


def blind_baoding(robot: str, config: str, overrides: list[str] = (), steps: int = 1, seed: int = 0):
    """The run spec of a blind Baoding cell as roto's Baoding studies train it (128 envs, one thread)."""
    from roto.rl.run_spec import build_run_spec

    return build_run_spec("baoding", robot, "blind", config, list(overrides), steps, num_envs=128, threads=1, seed=seed)


ROUND_BANK = earlier("round_bank")
"""baoding_cpu as the round-bank and round-swaps studies trained it, before it took armed round swaps."""
ARMED = ["env.aids.round_swaps={min_turn: 0.25, first_paid: true, after: 2}"]
HOLD = earlier("hold")
"""baoding_cpu as the hold-start study and the studies after it trained it (today's baoding_cpu)."""


def test_baoding_cpu_is_the_armed_recipe_started_at_the_hold_pose_as_the_studies_trained_them():
    """The packaged one-for-every-hand recipe is, on each hand, the frozen round-bank recipe plus
    round swaps armed after 2 rotations (what experiments/baoding_armed_round_swaps trained as
    armed_round, frozen as baoding_cpu_armed) with the policy started at the hold pose (frozen as
    baoding_cpu_hold): what experiments/baoding_hold_start trained, so that study's results are
    baoding_cpu's."""
    from roto.olympiad.cell import cell_spec

    for robot in ROBOTS:
        armed = blind_baoding(robot, earlier("armed"))
        assert armed.differences(blind_baoding(robot, ROUND_BANK, ARMED)) == {}
        hold = blind_baoding(robot, HOLD)
        assert hold.differences(armed) == {"agent.network.start_at_hold": (True, False)}
        assert blind_baoding(robot, "baoding_cpu").differences(hold) == {}
    for name in ("armed", "armed_untuned"):
        study = plan_named(name)
        for cell in study.cells:
            assert cell_spec(study, cell).differences(blind_baoding(cell.robot, earlier("armed"), seed=cell.seed)) == {}


def assert_hold_recipe_cells_but(name: str, cells: list[tuple[str, int]], differences: dict):
    """Plan ``name`` holds exactly ``cells`` ((robot, seed), in order), each the blind Baoding cell of
    ``baoding_cpu_hold`` on that hand and seed at the plan's budget but for ``differences``; the plan."""
    plan = plan_named(name)
    assert [(c.robot, c.seed) for c in plan.cells] == cells
    for cell in plan.cells:
        assert plan.steps_for(cell) == plan.steps
        assert against_the_recipe(plan, cell) == differences
    return plan


def against_the_recipe(plan, cell: Cell) -> dict:
    """Where a plan's blind Baoding cell differs from ``baoding_cpu_hold``'s cell of its hand, seed
    and budget: {key: (the cell's value, the recipe's)}."""
    from roto.olympiad.cell import cell_spec

    own = blind_baoding(cell.robot, HOLD, steps=plan.steps_for(cell), seed=cell.seed)
    return cell_spec(plan, cell).differences(own)


def test_the_hold_start_study_is_the_frozen_hold_recipe():
    """experiments/baoding_hold_start trained baoding_cpu_hold (today's baoding_cpu), seeds 0-9 of the
    blind Shadow."""
    assert_hold_recipe_cells_but("hold_start", [("shadow", s) for s in range(10)], {})


def test_the_kl_target_study_is_baoding_cpu_with_only_its_kl_target_doubled():
    """experiments/baoding_kl_target pairs each seed with baoding_hold_start's run of baoding_cpu."""
    doubled = {"agent.ppo.kl_target": (0.016, 0.008)}
    assert_hold_recipe_cells_but("kl_target", [("shadow", s) for s in range(5)], doubled)


def test_the_turn_near_probe_is_the_allegros_baoding_cpu_cell_with_only_its_turn_shaping_gated():
    """experiments/baoding_turn_near probes the Allegro's seed 1, which baoding_cpu left turning off the targets."""
    plan = assert_hold_recipe_cells_but("turn_near", [("allegro", 1)], {"env.aids.turn_shaping.near": (1.5, None)})
    assert [c.name for c in plan.cells] == ["baoding-allegro-blind-near_1_5-seed1"] and plan.steps == 10_000_000


def test_the_every_hand_hold_study_trains_exactly_the_benchmarks_blind_baoding_cells_of_the_other_hands():
    """experiments/baoding_hold_every_hand's cells are the benchmark's (same names and run specs), so
    its summaries count there; seed 0 of every hand trains before any hand's seed 1."""
    from roto.olympiad.cell import cell_spec

    plan, benchmark = plan_named("hold_every_hand"), load_plan("benchmark")
    others = {robot for robot in ROBOTS if robot != "shadow"}
    assert [c.seed for c in plan.cells] == sorted(c.seed for c in plan.cells)
    assert sorted((c.robot, c.obs, c.seed) for c in plan.cells) == sorted(
        (robot, "blind", seed) for seed in range(5) for robot in others
    )
    shared = {c.name: c for c in benchmark.cells}
    for cell in plan.cells:
        assert cell_spec(plan, cell).differences(cell_spec(benchmark, shared[cell.name])) == {}


def test_the_without_round_swaps_study_trains_every_baoding_cell_of_the_benchmark_with_only_round_swaps_off():
    """experiments/baoding_without_round_swaps holds each of the benchmark's Baoding cells (same names,
    budgets and seeds), each differing from it in the round swaps alone, so its summaries count there
    once baoding_cpu drops them; the ablation's hold_no_round_swaps runs are exactly its cells."""
    from roto.olympiad.adopt import same_run
    from roto.olympiad.cell import cell_spec

    plan, benchmark = plan_named("without_round_swaps"), load_plan("benchmark")
    theirs = {c.name: c for c in benchmark.cells if c.task == "baoding"}
    assert sorted(c.name for c in plan.cells) == sorted(theirs) and len(plan.cells) == 44
    assert [c.seed for c in plan.cells] == sorted(c.seed for c in plan.cells)
    for cell in plan.cells:
        mine, benchmarks = cell_spec(plan, cell), cell_spec(benchmark, theirs[cell.name])
        assert mine.steps == benchmarks.steps
        assert set(mine.differences(benchmarks)) == {"env.aids.round_swaps"}
        assert mine.env.aids.round_swaps is None and benchmarks.env.aids.round_swaps is not None
    ablations = plan_named("ablations_hold")
    adopted = {
        same_run(ablations, cell, plan).name
        for cell in ablations.cells
        if cell.variant == "hold_no_round_swaps" and same_run(ablations, cell, plan) is not None
    }
    assert adopted == {f"baoding-shadow-blind-ppo-seed{s}" for s in range(5)} | {"baoding-orca-blind-ppo-seed0"}


def assert_continues_at_20_m(longer_name: str, study_name: str) -> list:
    """Plan ``longer_name``'s cells are plan ``study_name``'s of the same names but for their budget
    (20 M against 10 M), so a run directory copied over from there continues (Trainer.open); its cells."""
    from roto.olympiad.cell import cell_spec

    longer, study = plan_named(longer_name), plan_named(study_name)
    shared = {c.name: c for c in study.cells}
    assert longer.cells
    for cell in longer.cells:
        mine, theirs = cell_spec(longer, cell), cell_spec(study, shared[cell.name])
        assert mine.differences(theirs) == {}
        assert (mine.steps, theirs.steps) == (20_000_000, 10_000_000)
    return longer.cells


def test_the_allegros_20m_plan_continues_the_every_hand_studys_allegro_cells_with_only_a_larger_budget():
    """experiments/baoding_hold_every_hand/allegro_20m.yaml continues hold_every_hand's Allegro cells."""
    cells = assert_continues_at_20_m("allegro_20m", "hold_every_hand")
    assert {c.robot for c in cells} == {"allegro"}


def test_the_round_bank_recipe_is_what_the_round_bank_study_trained_and_before_its_bank_what_the_others_did():
    """The frozen round-bank recipe is, on each hand, the Shadow's earlier recipe with the hand's
    round bank and the smaller encoder: what experiments/baoding_round_bank trained as
    small_round_bank (as overrides of the earlier baoding_cpu_shadow). With the hand's swinging bank
    pinned, it is what the every-hand pilot, the small-net study and the round bank's paired
    baseline trained (baoding_cpu before that study's decision)."""
    from roto.olympiad.cell import cell_spec

    for robot in ROBOTS:
        assert blind_baoding(robot, ROUND_BANK).env.aids.replayed_starts.bank == f"{robot}_round_preswap"
        for bank in (f"{robot}_round_preswap", f"{robot}_preswap"):
            pin = [f"env.aids.replayed_starts.bank={bank}"]
            as_trained = blind_baoding(robot, earlier("shadow"), [*pin, "network.encoder=[512, 256, 128]"])
            assert blind_baoding(robot, ROUND_BANK, pin).differences(as_trained) == {}
    study = plan_named("round_bank")
    swinging = {"env.aids.replayed_starts.bank": ("shadow_preswap", "shadow_round_preswap")}
    for cell in study.cells:
        differences = cell_spec(study, cell).differences(blind_baoding(cell.robot, ROUND_BANK, seed=cell.seed))
        assert differences == ({} if cell.variant == "small_round_bank" else swinging)
    for name in ("every_hand", "small_net"):
        study = plan_named(name)
        for cell in study.cells:
            pin = [f"env.aids.replayed_starts.bank={cell.robot}_preswap"]
            assert cell_spec(study, cell).differences(blind_baoding(cell.robot, ROUND_BANK, pin, seed=cell.seed)) == {}


def test_each_part_of_baoding_cpu_is_switched_off_by_exactly_one_ablation():
    """experiments/baoding_ablations: every cell is baoding_cpu as the armed study trained it
    (experiments/baoding_configs/baoding_cpu_armed.yaml) with one part off, one variant a part."""
    from roto.olympiad.cell import cell_spec

    plan = plan_named("ablations")
    recipe = blind_baoding("shadow", earlier("armed"), steps=plan.steps)
    replayed = {"bank": "shadow_round_preswap", "share": 0.5, "record_lead": 10, "record_capacity": 1024}
    expected = {
        "no_round_swaps": {"env.aids.round_swaps": (None, {"min_turn": 0.25, "first_paid": True, "after": 2})},
        "no_turn_shaping": {"env.aids.turn_shaping": (None, TURN_SHAPING)},
        "no_replayed_starts": {"env.aids.replayed_starts": (None, replayed)},
        "no_recording": {"env.aids.replayed_starts.record_lead": (0, 10)},
        "no_tolerance": {
            "env.aids.tolerance": (None, {"start": 0.025, "target": 2, "by": "headline", "deadline": None})
        },
        "std_1": {"agent.network.init_log_std": (0.0, -1.386), "agent.network.max_log_std": (0.0, -1.386)},
        "plain_critic": {"agent.network.critic": (None, ["tactile", "proprio", "privileged", "task"])},
    }
    assert sorted({c.variant for c in plan.cells}) == sorted(expected) and {c.seed for c in plan.cells} == {0, 1, 2}
    for cell in plan.cells:
        assert cell_spec(plan, cell).differences(recipe.with_seed(cell.seed)) == expected[cell.variant], cell.variant


def test_each_part_of_todays_baoding_cpu_is_switched_off_by_exactly_one_hold_ablation():
    """experiments/baoding_ablations/ablations_hold.yaml: every cell is today's baoding_cpu (the
    hold-pose start) with one part off, on seeds 0-2 the same parts as the armed recipe's
    ablations; a removal candidate's further cells (the Shadow's seeds 3 and 4, ORCA's seed 0 at
    10 M) differ from the recipe's cell of their hand, seed and budget by that part alone."""
    from roto.olympiad.cell import cell_spec

    plan, armed = plan_named("ablations_hold"), plan_named("ablations")
    recipe = blind_baoding("shadow", HOLD, steps=plan.steps)
    first = [c for c in plan.cells if c.robot == "shadow" and c.seed in (0, 1, 2)]
    assert len(first) == len(armed.cells)
    for cell in first:
        part = cell.variant.removeprefix("hold_")
        same_part = cell_spec(armed, Cell("baoding", "shadow", "blind", part, cell.seed))
        expected = cell_spec(plan, cell).differences(recipe.with_seed(cell.seed))
        assert expected and expected == same_part.differences(
            blind_baoding("shadow", earlier("armed"), steps=plan.steps, seed=cell.seed)
        )
        assert cell_spec(plan, cell).differences(same_part) == {"agent.network.start_at_hold": (True, False)}
    further = [c for c in plan.cells if c not in first]
    assert {(c.robot, c.seed, plan.steps_for(c)) for c in further} == {
        ("shadow", 3, 5_000_000), ("shadow", 4, 5_000_000), ("orca", 0, 10_000_000)
    }  # fmt: skip
    for cell in further:  # the part is off as on seed 0; the recipe's side is the hand's own (its bank)
        same_seed_0 = Cell("baoding", "shadow", "blind", cell.variant, 0)
        assert switched_off(plan, cell) == switched_off(plan, same_seed_0)


def switched_off(plan, cell: Cell) -> dict:
    """What a plan's blind Baoding cell sets where it differs from ``baoding_cpu_hold``'s cell of its
    hand, seed and budget, the recipe's side left out (each hand's recipe names its own bank)."""
    return {key: mine for key, (mine, _) in against_the_recipe(plan, cell).items()}


@pytest.mark.parametrize(
    "name, variant, seeds, pin, after",
    [  # first_paid's pair baoding_cpu's runs from before its round bank; the others today's
        ("first_paid", "first_paid", range(5), ["env.aids.replayed_starts.bank=shadow_preswap"], None),
        ("first_paid_untuned", "first_paid", range(5, 10), ["env.aids.replayed_starts.bank=shadow_preswap"], None),
        ("round_recipe", "round_first_paid", range(5), [], None),
        ("round_recipe_untuned", "round_first_paid", range(5, 10), [], None),
        ("armed", "armed_round", range(5), [], 2.0),
        ("armed_untuned", "armed_round", range(5, 10), [], 2.0),
    ],
)
def test_the_first_paid_plans_are_baoding_cpu_with_round_swaps_paying_the_first_swap(name, variant, seeds, pin, after):
    """Their cells differ from the baoding_cpu runs they pair with seed by seed (experiments/
    baoding_small_net and baoding_round_bank) only by the round-swaps aid with first_paid (armed
    after 2 rotations in experiments/baoding_armed_round_swaps)."""
    from roto.olympiad.cell import cell_spec

    plan = plan_named(name)
    assert [(c.robot, c.variant, c.seed) for c in plan.cells] == [("shadow", variant, s) for s in seeds]
    for cell in plan.cells:
        recipe = blind_baoding("shadow", ROUND_BANK, pin, plan.steps, seed=cell.seed)
        differences = cell_spec(plan, cell).differences(recipe)
        assert differences == {"env.aids.round_swaps": ({"min_turn": 0.25, "first_paid": True, "after": after}, None)}


def test_the_turn_pay_study_is_baoding_cpu_with_only_its_turn_shaping_doubled():
    """experiments/baoding_turn_pay pairs each seed with baoding_hold_start's run of baoding_cpu."""
    doubled = {"env.aids.turn_shaping.per_turn": (40.0, 20.0)}
    assert_hold_recipe_cells_but("turn_pay", [("shadow", s) for s in range(5)], doubled)


def test_the_turn_soft_probe_is_the_allegros_baoding_cpu_cells_with_only_its_turn_shaping_falling_off():
    """experiments/baoding_turn_soft probes the Allegro's seeds 1 and 3, which baoding_cpu left off the targets."""
    falling = {"env.aids.turn_shaping.near": (1.0, None), "env.aids.turn_shaping.soft": (True, False)}
    plan = assert_hold_recipe_cells_but("turn_soft", [("allegro", 1), ("allegro", 3)], falling)
    assert plan.steps == 10_000_000


def test_the_wide_latch_probe_is_the_allegros_baoding_cpu_cells_with_only_its_latch_starting_at_5_cm():
    """experiments/baoding_wide_latch probes the Allegro's seeds 1 and 3, which baoding_cpu left off the targets."""
    wide = {"env.aids.tolerance.start": (0.05, 0.025)}
    plan = assert_hold_recipe_cells_but("wide_latch", [("allegro", 1), ("allegro", 3)], wide)
    assert plan.steps == 10_000_000


def test_the_forward_dynamics_study_is_baoding_cpu_with_only_roto_s_memory_loss_added():
    """experiments/baoding_forward_dynamics pairs each seed with baoding_hold_start's run of baoding_cpu."""
    from roto.rl.ssl.configs import ForwardDynamicsMemoryConfig

    loss = ForwardDynamicsMemoryConfig(weight=0.025, lr=2.5e-4, seq_length=2)
    added = {"agent.ssl.forward_dynamics_memory": (json.loads(json.dumps(dataclasses.asdict(loss))), None)}
    assert_hold_recipe_cells_but("forward_dynamics", [("shadow", s) for s in range(5)], added)


def test_the_std_free_study_is_baoding_cpu_with_its_std_projected_and_no_entropy_bonus():
    """experiments/baoding_std_free pairs each seed with baoding_hold_start's run of baoding_cpu."""
    free = {"agent.network.project_log_std": (True, False), "agent.ppo.entropy_coef": (0.0, 0.05)}
    assert_hold_recipe_cells_but("std_free", [("shadow", s) for s in range(5)], free)


def test_the_low_noise_study_is_baoding_cpu_with_its_std_bounded_at_0_15():
    """experiments/baoding_low_noise pairs each seed with baoding_hold_start's run of baoding_cpu."""
    lower = {"agent.network.init_log_std": (-1.897, -1.386), "agent.network.max_log_std": (-1.897, -1.386)}
    assert_hold_recipe_cells_but("low_noise", [("shadow", s) for s in range(5)], lower)


def test_the_turn_soft_continuation_is_its_probes_cell_at_20_m():
    """experiments/baoding_turn_soft/turn_soft_20m.yaml continues the probe's cells."""
    assert [c.seed for c in assert_continues_at_20_m("turn_soft_20m", "turn_soft")] == [1]


def test_the_turn_focus_probe_is_the_allegros_baoding_cpu_cells_with_a_narrowing_near_at_20_m():
    """experiments/baoding_turn_focus probes the Allegro's seeds 1 and 3, which baoding_cpu left off the targets."""
    focus = {
        "env.aids.turn_shaping.near": (1.0, None),
        "env.aids.turn_shaping.soft": (True, False),
        "env.aids.turn_shaping.near_from": (3.0, None),
    }
    plan = assert_hold_recipe_cells_but("turn_focus", [("allegro", 1), ("allegro", 3)], focus)
    assert plan.steps == 20_000_000


def test_the_turn_latch_probe_is_turn_focus_with_the_latch_narrowing_by_net_turns():
    """experiments/baoding_turn_latch: turn_focus's cells with the tolerance measured by net turns."""
    focus = {
        "env.aids.turn_shaping.near": (1.0, None),
        "env.aids.turn_shaping.soft": (True, False),
        "env.aids.turn_shaping.near_from": (3.0, None),
        "env.aids.tolerance.by": ("net_turns", "headline"),
    }
    plan = assert_hold_recipe_cells_but("turn_latch", [("allegro", 1), ("allegro", 3)], focus)
    assert plan.steps == 20_000_000


def test_the_latch_deadline_probe_is_the_allegros_baoding_cpu_with_only_a_deadline():
    """experiments/baoding_latch_deadline: the Allegro's cells with the latch at 1 cm from 5 M on."""
    deadline = {"env.aids.tolerance.deadline": (5_000_000, None)}
    plan = assert_hold_recipe_cells_but("latch_deadline", [("allegro", 0), ("allegro", 4)], deadline)
    assert plan.steps == 10_000_000


def test_the_drop_penalty_study_is_the_benchmarks_bounce_cells_with_only_the_aid():
    """experiments/bounce_drop_penalty pairs each cell with the benchmark's run of the same hand, mode and seed."""
    from roto.olympiad.cell import cell_spec

    plan, benchmark = plan_named("drop_penalty"), plan_named("benchmark")
    hands, modes = ("shadow_lite", "allegro"), ("state", "proprio")
    pairs = {(robot, obs, seed) for robot in hands for obs in modes for seed in (0, 1)}
    assert {(c.robot, c.obs, c.seed) for c in plan.cells} == pairs and plan.steps == benchmark.steps
    for cell in plan.cells:
        same = cell_spec(benchmark, Cell("bounce", cell.robot, cell.obs, "ppo", cell.seed))
        assert cell_spec(plan, cell).differences(same) == {"env.aids.drop_penalty": ({"per_drop": 10.0}, None)}


def test_the_hold_noise_probe_bounds_the_allegros_std_at_the_noise_its_hold_tolerates():
    """experiments/baoding_hold_noise probes the Allegro's seeds 1 and 3 with the std its hold pose tolerates."""
    from roto.reference.hold import tolerated_noise

    rows = json.loads((ROOT / "benchmarks/results/baoding_reference/hold_noise.json").read_text())
    noise = tolerated_noise(rows, "allegro")
    assert noise == 0.15
    log_std = round(math.log(noise), 3)  # the plan's value, derived from the hand's tolerated noise
    lower = {"agent.network.init_log_std": (log_std, -1.386), "agent.network.max_log_std": (log_std, -1.386)}
    plan = assert_hold_recipe_cells_but("hold_noise", [("allegro", 1), ("allegro", 3)], lower)
    assert plan.steps == 10_000_000


def test_the_lean_recipe_is_baoding_cpu_with_its_two_bank_aids_off_on_every_hand():
    """experiments/baoding_lean/lean.yaml: each cell is the recipe's cell of its hand, seed and
    budget with the replayed starts and the round swaps switched off, nothing else."""
    plan = plan_named("lean")
    assert {(c.robot, c.seed, plan.steps_for(c)) for c in plan.cells} == {
        *(("shadow", seed, 5_000_000) for seed in range(5)), ("orca", 0, 10_000_000), ("allegro", 0, 10_000_000)
    }  # fmt: skip
    for cell in plan.cells:
        assert switched_off(plan, cell) == {"env.aids.replayed_starts": None, "env.aids.round_swaps": None}


def test_dry_run_of_a_finished_plan_says_no_time_is_left(capsys):
    """The committed benchmark cells are the whole plan: nothing left, no rate to estimate at."""
    from roto.cli import main

    results = ROOT / "benchmarks" / "results" / "benchmark" / "cells"
    assert main(["olympiad", "benchmark", "--dry-run", "--results", str(results)]) == 0
    assert "80 done, 0 left; time left: none, every cell has finished" in capsys.readouterr().out

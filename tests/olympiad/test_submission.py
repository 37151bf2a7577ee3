import copy
import json

import numpy as np
import pytest
import torch

from roto.cli import main
from roto.envs.config import EnvConfig
from roto.eval.evaluate import evaluate_policy
from roto.eval.protocol import EVAL_SEED
from roto.olympiad.stats import iqm
from roto.olympiad.submission import check_submission, make_submission, submission_summaries
from tests.olympiad.test_results import write_summaries

ROUND = {0: 9.0, 1: 11.0, 2: 13.0}  # every episode of seed s makes ROUND[s] round rotations


def episodes(seed: int, n: int = 100) -> dict[str, list[float]]:
    """Baoding's per-episode measures of one seed: round rotations ROUND[seed] +/- 1 alternating."""
    rounds = [ROUND[seed] + (1.0 if i % 2 else -1.0) for i in range(n)]
    return {
        "swaps": [2 * r for r in rounds],
        "rotations": rounds,
        "net_turns": [r + 0.5 for r in rounds],
        "travelled_turns": [r + 1.0 for r in rounds],
        "round_rotations": rounds,
    }


def baoding_submission() -> dict:
    return {
        "format": 1,
        "task": "baoding",
        "task_version": 1,
        "robot": "shadow",
        "obs": "blind",
        "touch": "binary",
        "method": {"name": "my_method", "description": "PPO with a recurrent encoder"},
        "env_steps": 5_000_000,
        "evaluation": {"episodes": 100, "seed": EVAL_SEED, "training_aids": {}},
        "seeds": [{"seed": s, "per_episode": episodes(s)} for s in ROUND],
    }


def test_a_submission_becomes_one_summary_per_seed_with_its_episodes_means():
    summaries = submission_summaries(check_submission("ok.json", baoding_submission()), "ok.json")
    assert [s["seed"] for s in summaries] == [0, 1, 2]
    assert {s["variant"] for s in summaries} == {"my_method"} and summaries[0]["plan"] == "submission ok.json"
    for s in summaries:
        assert s["final"] == s["best"] and s["evaluations"] == []
        assert s["best"]["round_rotations_mean"] == ROUND[s["seed"]]  # +1 and -1 alternate over 100 episodes
        assert s["best"]["round_rotations_std"] == 1.0 and s["best"]["rotations_mean"] == ROUND[s["seed"]]
        assert next(iter(s["best"])) == "round_rotations_mean"  # Baoding's lead measure first
    assert "touch binary, 5,000,000 env steps" in summaries[0]["agent"]["label"]


def edit(change):
    data = baoding_submission()
    change(data)
    return data


BAD = [
    (lambda d: d.pop("robot"), "lacks the field(s) ['robot']"),
    (lambda d: d.update(task_version=0), "'task_version' is 0, but this roto's baoding is version 1"),
    (lambda d: d.update(task="juggle"), "'task' is 'juggle'; valid: ['baoding', 'bounce']"),
    (lambda d: d.update(robot="robonaut"), "'robot' is 'robonaut'; valid: ["),
    (lambda d: d.update(obs="xray"), "'obs' is 'xray'; valid: ['blind', 'state', 'proprio']"),
    (lambda d: d.update(obs="proprio"), "'touch (obs proprio)' is 'binary'; valid: ['none']"),
    (lambda d: d.update(touch="none"), "'touch (obs blind)' is 'none'; valid: ['binary', 'force', 'taxels']"),
    (lambda d: d.update(format=2), "is a submission of format 2; this roto reads submission formats 1 to 1"),
    (lambda d: d.update(env_steps="5M"), "'env_steps' should be an integer, found a string ('5M')"),
    (lambda d: d.update(env_steps=0), "'env_steps' (the training budget per seed) should be >= 1, got 0"),
    (lambda d: d["method"].update(name="My Method"), "method 'name' 'My Method' should be 1-40 characters"),
    (lambda d: d["method"].pop("description"), "'method' lacks the field(s) ['description']"),
    (lambda d: d["method"].update(url="github.com/me/x"), "method 'url' should be a web address (http:// or https"),
    (lambda d: d["method"].update(url=7), "method 'url' should be a web address (http:// or https://...), got 7"),
    (lambda d: d["method"].update(commit=""), "method 'commit' should be a string, got ''"),
    (lambda d: d["evaluation"].update(episodes=99), "'episodes' is 99; roto's protocol evaluates >= 100 episodes"),
    (lambda d: d["evaluation"].update(seed=0), "'seed' is 0; roto's protocol evaluates from seed 1000000"),
    (
        lambda d: d["evaluation"].update(training_aids={"turn_shaping": {"per_turn": 20}}),
        "'training_aids' is {'turn_shaping': {'per_turn': 20}}; evaluation is the benchmark's own task",
    ),
    (lambda d: d["seeds"].pop(), "'seeds' holds 2 training seed(s); a submission holds >= 3"),
    (lambda d: d["seeds"][2].update(seed=0), "seeds[2]: training seed 0 appears twice"),
    (lambda d: d["seeds"][1]["per_episode"].pop("net_turns"), "seeds[1]: per_episode 'net_turns' should be a list"),
    (lambda d: d["seeds"][0]["per_episode"]["rotations"].pop(), "'rotations' holds 99 values; 'evaluation' says 100"),
    (lambda d: d["seeds"][0]["per_episode"]["swaps"].__setitem__(3, float("nan")), "holds a number (nan); every"),
    (lambda d: d["seeds"][0]["per_episode"]["swaps"].__setitem__(3, True), "holds a boolean (True); every"),
]


@pytest.mark.parametrize(("change", "message"), BAD)
def test_a_submission_that_cannot_stand_in_the_table_is_refused_naming_the_field(change, message):
    with pytest.raises(ValueError, match=r"submission 'bad\.json'") as error:
        check_submission("bad.json", edit(change))
    assert message in str(error.value)


def test_a_bounce_submission_needs_only_bounces_and_a_proprio_one_touch_none():
    data = edit(lambda d: d.update(task="bounce", task_version=0, obs="proprio", touch="none"))
    for entry in data["seeds"]:
        entry["per_episode"] = {"bounces": entry["per_episode"]["rotations"]}
    [summary, *_] = submission_summaries(check_submission("b.json", data))
    assert summary["best"]["bounces_mean"] == ROUND[0] and "round_rotations_mean" not in summary["best"]


def eval_file(folder, train_seed: int, **changes) -> str:
    """What roto eval writes for a blind Shadow Baoding checkpoint trained on ``train_seed``."""
    path = folder / f"eval_seed{train_seed}.json"
    data = {"checkpoint": f"runs/x-seed{train_seed}/checkpoints/best.pt", "task": "baoding", "task_version": 1}
    data |= {"robot": "shadow", "obs": "blind", "touch": "binary", "train_seed": train_seed, "episodes": 100}
    per_episode = {"return": [1.0] * 100, "length": [600.0] * 100, **episodes(train_seed)}
    data |= {"seed": EVAL_SEED, "per_episode": per_episode}
    path.write_text(json.dumps(data | changes))
    return str(path)


def test_submit_check_and_results_set_a_method_beside_the_baselines(tmp_path, capsys):
    files = [eval_file(tmp_path, seed) for seed in ROUND]
    submitted = tmp_path / "submissions" / "mine.json"
    args = ["--method", "my_method", "--description", "PPO with a recurrent encoder", "--env_steps", "5000000"]
    assert main(["submit", *files, *args, "--out", str(submitted)]) == 0
    assert json.loads(capsys.readouterr().out.splitlines()[-1]) == {
        "submission": str(submitted),
        "method": "my_method",
        "seeds": [0, 1, 2],
    }
    assert main(["results", "--check", str(submitted)]) == 0
    checked = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert checked["valid"] and checked["seeds"] == [0, 1, 2] and checked["robot"] == "shadow"
    write_summaries(tmp_path / "baselines")
    out = tmp_path / "out"
    assert (
        main(["results", str(tmp_path / "baselines"), "--submissions", str(submitted.parent), "--out", str(out)]) == 0
    )
    md = (out / "results.md").read_text()
    lead = md[md.index("## best policy: baoding") : md.index("## final policy")]
    scores = np.array(list(ROUND.values()))
    expected = f"{scores.mean():.1f} ± {scores.std():.1f} (IQM {iqm(scores):.1f}"
    assert "baoding (v1) / blind / my_method: PPO with a recurrent encoder (submitted; touch binary" in lead
    assert f"| shadow | {expected}" in lead  # the method's round rotations, with the baselines' statistics
    assert "my_method" in (out / "results_final.csv").read_text()


def test_submit_refuses_files_of_different_cells_or_evaluation_seeds(tmp_path):
    args = ["--method", "m", "--description", "d", "--env_steps", "5", "--out", str(tmp_path / "s.json")]
    files = [eval_file(tmp_path, 0), eval_file(tmp_path, 1), eval_file(tmp_path, 2, robot="allegro")]
    with pytest.raises(ValueError, match="the files evaluate different cells"):
        _submit(files, args)
    files[2] = eval_file(tmp_path, 2, seed=7)
    with pytest.raises(ValueError, match=r"evaluated with different 'seed' \['1000000', '7'\]"):
        _submit(files, args)
    with pytest.raises(ValueError, match="evaluates training seed 0 again"):
        _submit([files[0], files[0], files[1]], args)
    (tmp_path / "number.json").write_text("7")
    with pytest.raises(ValueError, match=r"holds an integer \(7\): not a file of roto eval"):
        _submit([files[0], files[1], str(tmp_path / "number.json")], args)
    (tmp_path / "other.json").write_text(json.dumps({"task": "baoding"}))
    with pytest.raises(ValueError, match=r"lacks \['robot', 'obs', 'touch', 'train_seed', 'per_episode'\]"):
        _submit([files[0], files[1], str(tmp_path / "other.json")], args)
    assert not (tmp_path / "s.json").exists()


def _submit(files, args):
    from roto.cli import build_parser

    parsed = build_parser().parse_args(["submit", *files, *args])
    return parsed.func(parsed)


def test_a_method_named_as_a_baseline_column_is_refused(tmp_path):
    from roto.olympiad.results_page import write_results

    write_summaries(tmp_path / "baselines")
    data = edit(lambda d: d.update(robot="allegro"))
    data["method"]["name"] = "ppo"  # the baselines' Allegro Baoding column
    (tmp_path / "subs").mkdir()
    (tmp_path / "subs" / "dup.json").write_text(json.dumps(data))
    with pytest.raises(ValueError, match="method 'ppo' is already a column of baoding/allegro/blind"):
        write_results(tmp_path / "baselines", tmp_path / "out", submissions=str(tmp_path / "subs"))
    assert not (tmp_path / "out").exists()


def test_results_check_stands_alone(tmp_path, capsys):
    assert main(["results", "--check", "x.json", "--out", str(tmp_path)]) == 2
    assert "checks one submission and writes nothing" in capsys.readouterr().err
    assert main(["results", "--check", str(tmp_path / "missing.json")]) == 2
    assert "submission" in capsys.readouterr().err


def test_evaluate_policy_shows_a_blind_policy_only_its_groups_and_makes_a_submission(tmp_path):
    seen = []

    def still(obs):
        seen.append(sorted(obs))
        return torch.zeros(next(iter(obs.values())).shape[0], 20)

    config = EnvConfig(task="baoding", robot="shadow", obs_mode="blind")
    result = evaluate_policy(still, config, episodes=2, seed=EVAL_SEED)
    assert result["seed"] == EVAL_SEED and result["episodes"] == 2 and len(result["per_episode"]["net_turns"]) == 2
    assert {tuple(groups) for groups in seen} == {("proprio", "tactile")}  # no "privileged": the balls' state
    with pytest.raises(ValueError, match="'episodes' is 2; roto's protocol evaluates >= 100 episodes"):
        make_submission(config, {s: copy.deepcopy(result) for s in ROUND}, {"name": "m", "description": "d"}, 10)

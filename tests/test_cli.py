import json

from roto.cli import main


def test_list_prints_every_pair_with_sizes(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert "roto/Bounce-Shadow-v0" in out and "roto/Baoding-Shadow-v1" in out
    assert "97" in out and "388" in out
    assert "frame (taxels)" in out and "143" in out  # Shadow: 97 + 46 taxels


def test_bench_json_has_the_contract_fields(capsys):
    assert main(["bench", "--task", "baoding", "--num_envs", "4", "--steps", "8", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    for key in ("env_steps_per_s", "raw_physics_steps_per_s", "substeps", "threads", "efficiency"):
        assert key in result
    expected = result["env_steps_per_s"] * result["substeps"] / (result["threads"] * result["raw_physics_steps_per_s"])
    assert abs(result["efficiency"] - expected) < 1e-2


def test_bad_task_is_a_clear_error(capsys):
    assert main(["bench", "--task", "juggle", "--num_envs", "2", "--steps", "1"]) == 2
    assert "unknown task 'juggle'" in capsys.readouterr().err


def test_demo_runs_the_scripted_policy(capsys):
    assert main(["demo", "--num_envs", "2", "--episodes", "1"]) == 0
    stats = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert stats["episodes"] == 2 and stats["mean_bounces"] >= 0


def test_baoding_demo_refuses_what_the_reference_controller_cannot_do(capsys, tmp_path):
    assert main(["demo", "--task", "baoding", "--backend", "warp"]) == 2
    assert "the Baoding reference controller plans on 'cpu' only" in capsys.readouterr().err
    assert main(["demo", "--task", "baoding", "--preswap_out", str(tmp_path)]) == 2
    assert f"--preswap_out {str(tmp_path)!r} is a directory" in capsys.readouterr().err
    assert main(["demo", "--task", "bounce", "--preswap_out", str(tmp_path / "s.npz")]) == 2
    assert "--preswap_out, --preswap_leads and --turn_weight are for --task baoding" in capsys.readouterr().err
    assert main(["demo", "--task", "bounce", "--turn_weight", "3"]) == 2
    assert "--turn_weight are for --task baoding" in capsys.readouterr().err
    assert main(["demo", "--task", "baoding", "--turn_weight", "-2"]) == 2
    assert "--turn_weight -2.0: must be a weight >= 0" in capsys.readouterr().err
    assert main(["demo", "--task", "baoding", "--preswap_leads", "10", "20"]) == 2
    assert "--preswap_leads [10, 20] records states for --preswap_out" in capsys.readouterr().err
    assert main(["demo", "--task", "baoding", "--episodes", "0"]) == 2
    assert "episodes must be an integer >= 1, got 0" in capsys.readouterr().err


def test_baoding_demo_passes_the_turn_weight_to_the_planner(capsys, monkeypatch):
    import roto.reference.baoding_controller as controller

    seen = {}

    def fake_run(**kwargs):
        seen.update(kwargs)
        return {"mean_rotations": 0.0}

    monkeypatch.setattr(controller, "run_reference_baoding", fake_run)
    assert main(["demo", "--task", "baoding", "--robot", "orca", "--turn_weight", "3"]) == 0
    assert seen["robot"] == "orca" and seen["weights"].turn == 3.0 and seen["weights"].distance == 10.0
    assert main(["demo", "--task", "baoding"]) == 0
    assert seen["weights"].turn == 0.0  # off unless asked: the published figures' cost


def test_the_env_flags_help_names_every_task_and_hand_roto_has(capsys):
    """The help's lists are written out (the CLI imports no hand models to print its help): they
    must name what the registries hold."""
    import argparse

    from roto.cli_args import add_env_args
    from roto.robots import ROBOTS
    from roto.tasks import TASKS

    parser = argparse.ArgumentParser()
    add_env_args(parser, num_envs=8)
    text = " ".join(parser.format_help().split())  # unwrapped
    assert f"--robot ROBOT hand: {', '.join(ROBOTS)} (default: shadow)" in text
    assert f"--task TASK task name: {', '.join(TASKS)} (default: bounce)" in text
    assert "worlds stepped side by side (default: 8)" in text

"""The tolerance curriculum: Baoding's latch radius starts wide, narrows as training episodes
rotate (or, by net turns, as the pair turns), is saved with the env, is refused where a task has no
radius, and never reaches evaluation."""

from types import SimpleNamespace

import pytest
import torch

import roto
from roto.envs.aids.episode_mean import EPISODE_WEIGHT, Narrowing
from roto.envs.aids.protocol import StepContext
from roto.envs.aids.settings import ToleranceSettings
from roto.envs.aids.tolerance import ToleranceAid
from roto.envs.config import EnvConfig
from roto.rl.run_spec import RunSpec
from roto.tasks.baoding import SUCCESS_RADIUS, baoding_rule


def curriculum(start=0.025, target=1.0):
    return Narrowing(start, SUCCESS_RADIUS, target, torch.zeros((), dtype=torch.float64))


def test_the_radius_narrows_with_the_running_mean_of_ended_episodes():
    c = curriculum()
    assert float(c.value()) == pytest.approx(0.025)
    done = torch.tensor([True, True, False, True])
    metric = torch.tensor([0.5, 0.5, 7.0, 0.5])  # the world still running does not count
    c.update(metric, done)
    # three episodes of 0.5, one at a time, each moving the mean a weight of EPISODE_WEIGHT towards 0.5
    mean = 0.0
    for _ in range(3):
        mean += EPISODE_WEIGHT * (0.5 - mean)
    assert float(c.mean) == pytest.approx(mean)
    assert float(c.value()) == pytest.approx(SUCCESS_RADIUS + 0.015 * (1.0 - mean))
    before = float(c.mean)
    c.update(metric, torch.zeros(4, dtype=torch.bool))  # nothing ended: nothing moves
    assert float(c.mean) == before
    for _ in range(2000):  # episodes at the target: the task's own radius
        c.update(torch.full((4,), 1.0), torch.ones(4, dtype=torch.bool))
    assert float(c.value()) == pytest.approx(SUCCESS_RADIUS, abs=1e-9)


def test_a_wider_radius_latches_a_ball_the_benchmarks_would_not():
    targets = torch.tensor([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]], dtype=torch.float64)
    pos = torch.tensor([[[0.02, 0.0, 0.0], [0.5, 0.0, 0.0]]], dtype=torch.float64)  # ball a 2 cm from T_a
    none = torch.zeros(1, dtype=torch.bool)
    latches = torch.zeros(1, 2, dtype=torch.bool)
    assert not baoding_rule(pos, targets, none, latches)[3].any()
    assert baoding_rule(pos, targets, none, latches, torch.tensor(0.025, dtype=torch.float64))[3][0, 0]


TOLERANCE = {"tolerance": {"start": 0.03, "target": 2.0}}


def test_a_baoding_env_starts_wide_narrows_as_its_episodes_rotate_and_resumes_exactly():
    env = roto.make("baoding", robot="shadow", num_envs=4, seed=0, aids=TOLERANCE)
    assert float(env.task_state.radius) == pytest.approx(0.03)
    env.reset()
    env.task_state.swaps.fill_(2)  # every world has made one rotation when its episode ends
    rotations = env.task.metrics(env.task_state)["rotations"]
    ended = torch.ones(4, dtype=torch.bool)
    env.aid(ToleranceAid).observe(StepContext(None, None, None, env.task_state, rotations, None, ended))
    mean = 1.0 - (1.0 - EPISODE_WEIGHT) ** 4
    assert float(env.task_state.radius) == pytest.approx(SUCCESS_RADIUS + 0.02 * (1.0 - mean / 2.0))
    saved = env.state_dict()
    other = roto.make("baoding", robot="shadow", num_envs=4, seed=5, aids=TOLERANCE)
    other.load_state_dict(saved)
    assert torch.equal(other.aid(ToleranceAid).curriculum.mean, env.aid(ToleranceAid).curriculum.mean)
    assert torch.equal(other.task_state.radius, env.task_state.radius)
    plain = roto.make("baoding", robot="shadow", num_envs=4, seed=0)
    assert plain.aid(ToleranceAid) is None and float(plain.task_state.radius) == SUCCESS_RADIUS


def test_by_net_turns_the_radius_narrows_as_the_pair_turns_with_no_latch_counted():
    aids = {"tolerance": {"start": 0.03, "target": 2.0, "by": "net_turns"}}
    env = roto.make("baoding", robot="allegro", num_envs=4, seed=0, aids=aids)
    env.reset()
    env.task_state.net_turn.copy_(torch.tensor([3.0, -3.0, 1.0, 9.0], dtype=torch.float64))  # either way round
    no_rotations = torch.zeros(4, dtype=torch.float64)
    ended = torch.tensor([True, True, True, False])
    env.aid(ToleranceAid).observe(StepContext(None, None, None, env.task_state, no_rotations, None, ended))
    sizes = torch.tensor([3.0, 3.0, 1.0, 9.0], dtype=torch.float64)  # the running world's 9 not counted
    expected = curriculum(start=0.03, target=2.0).update(sizes, ended)
    assert float(env.task_state.radius) == pytest.approx(float(expected)) and float(expected) < 0.0295
    by_rotations = roto.make("baoding", robot="allegro", num_envs=4, seed=0, aids=TOLERANCE)
    by_rotations.reset()
    by_rotations.task_state.net_turn.copy_(env.task_state.net_turn)
    by_rotations.aid(ToleranceAid).observe(
        StepContext(None, None, None, by_rotations.task_state, no_rotations, None, ended)
    )
    assert float(by_rotations.task_state.radius) == pytest.approx(0.03)  # no rotation: still wide


def test_past_its_deadline_the_radius_is_the_tasks_own_whatever_the_episodes_score_and_resumes():
    aids = {"tolerance": {"start": 0.03, "target": 2.0, "deadline": 12}}
    env = roto.make("baoding", robot="allegro", num_envs=4, seed=0, aids=aids)
    env.reset()
    aid = env.aid(ToleranceAid)
    none_ended = torch.zeros(4, dtype=torch.bool)
    no_rotations = torch.zeros(4, dtype=torch.float64)
    step = StepContext(None, None, None, env.task_state, no_rotations, None, none_ended)
    for _ in range(2):  # 8 of the 12 env steps: still the curriculum's, wide with no rotation
        aid.observe(step)
    assert float(env.task_state.radius) == pytest.approx(0.03)
    assert float(aid.metrics()["train/success_radius"]) == pytest.approx(0.03)
    saved = env.state_dict()
    aid.observe(step)  # 12 env steps: the deadline
    assert float(env.task_state.radius) == SUCCESS_RADIUS
    assert float(aid.metrics()["train/success_radius"]) == SUCCESS_RADIUS
    assert float(aid.curriculum.value()) == pytest.approx(0.03)  # the curriculum itself still wide
    resumed = roto.make("baoding", robot="allegro", num_envs=4, seed=3, aids=aids)
    resumed.load_state_dict(saved)
    resumed.aid(ToleranceAid).observe(StepContext(None, None, None, resumed.task_state, no_rotations, None, none_ended))
    assert resumed.aid(ToleranceAid).env_steps == 12 and float(resumed.task_state.radius) == SUCCESS_RADIUS
    without = roto.make("baoding", robot="allegro", num_envs=4, seed=0, aids=TOLERANCE)
    for _ in range(100):  # no deadline: the radius follows the episodes alone
        without.aid(ToleranceAid).observe(
            StepContext(None, None, None, without.task_state, no_rotations, None, none_ended)
        )
    assert float(without.task_state.radius) == pytest.approx(0.03)


@pytest.mark.parametrize(
    ("task", "settings", "pattern"),
    [
        ("bounce", {"start": 0.02}, r"aids.tolerance applies to a task with a success radius.*'bounce' has none"),
        (
            "baoding",
            {"start": 0.005},
            r"aids.tolerance.start must be a radius \(m\) no smaller than the task's own 0.01",
        ),
        ("baoding", {"start": 0.02, "target": 0.0}, r"aids.tolerance.target must be a mean of headline.*got 0.0"),
        ("baoding", {"start": -1.0}, r"got -1.0"),
        ("baoding", {"target": 2.0}, r"aids.tolerance needs \['start'\]"),
        (
            "baoding",
            {"start": 0.02, "by": "swaps"},
            r"tolerance.by must be one of \['headline', 'net_turns'\], got 'swaps'",
        ),
        ("baoding", {"start": 0.02, "deadline": 0}, r"aids.tolerance.deadline must be an integer >= 1, got 0"),
        (
            "baoding",
            {"start": 0.02, "deadline": 5e6},
            r"aids.tolerance.deadline must be an integer >= 1, got 5000000.0",
        ),
    ],
)
def test_bad_tolerance_settings_are_refused(task, settings, pattern):
    with pytest.raises(ValueError, match=pattern):
        EnvConfig(task=task, aids={"tolerance": settings})


def test_net_turns_need_a_ball_pair():
    latch_only = SimpleNamespace(name="latch", parameters={"success_radius": SUCCESS_RADIUS})
    ToleranceSettings(start=0.02).check("aids.tolerance", latch_only)
    with pytest.raises(ValueError, match=r"aids.tolerance.by applies to a task with a ball pair.*'latch' has none"):
        ToleranceSettings(start=0.02, by="net_turns").check("aids.tolerance", latch_only)


def test_evaluation_envs_use_the_benchmarks_radius():
    settings = RunSpec(env=EnvConfig(task="baoding", aids={"tolerance": {"start": 0.025}}))
    assert settings.eval_env_config(4).aids.tolerance is None and settings.cpu_env_config(1).aids.tolerance is None
    assert settings.env_config().aids.tolerance.start == 0.025


def test_training_logs_the_radius_and_config_yaml_names_the_aid(tmp_path):
    import csv

    import yaml

    from roto.cli import main
    from tests.test_cli_training import TINY

    run_dir = tmp_path / "run"
    args = [
        "train",
        "--task",
        "baoding",
        "--num_envs",
        "4",
        "--steps",
        "48",
        "--run_dir",
        str(run_dir),
        "--no_progress",
    ]
    assert main([*args, *TINY, "env.aids.tolerance.start=0.03"]) == 0
    radii = [
        float(r["value"])
        for r in csv.DictReader((run_dir / "scalars.csv").open())
        if r["tag"] == "train/success_radius"
    ]
    assert len(radii) == 3 and all(SUCCESS_RADIUS <= r <= 0.03 for r in radii)
    assert yaml.safe_load((run_dir / "config.yaml").read_text())["env"]["aids"] == {
        "tolerance": {"start": 0.03, "target": 1.0, "by": "headline", "deadline": None}
    }

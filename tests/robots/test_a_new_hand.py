"""A hand is data: a new hand, registered as docs/developer.md's "Adding a hand" says (its
RobotSpec with a record of each task, one entry in ROBOTS), runs every task, gets its Gymnasium
ids, trains its record's recipe in a plan, and takes its row in the results tables, with no task,
backend or table changed. The toy hand reuses the Shadow's model under records of its own."""

import dataclasses
from types import MappingProxyType

import pytest
import torch

import roto
from roto.robots import ROBOTS
from roto.robots.spec import PairRecord


def toy_hand():
    shadow = ROBOTS["shadow"]
    bounce = dataclasses.replace(shadow.tasks["bounce"], reference=3.0, recipe="bounce_cpu_orca")
    baoding = PairRecord(
        reference=1.5, warp_peaks=(12, 65), recipe="baoding_cpu_v1", geometry=shadow.tasks["baoding"].geometry
    )
    tasks = MappingProxyType({"bounce": bounce, "baoding": baoding})
    return dataclasses.replace(shadow, name="toy", display_name="Toy", tasks=tasks)


@pytest.fixture
def toy(monkeypatch):
    monkeypatch.setitem(roto.robots.ROBOTS, "toy", toy_hand())


@pytest.mark.parametrize("task", ["bounce", "baoding"])
def test_a_new_hand_runs_every_task_and_reads_its_own_records(task, toy):
    env = roto.make(task, robot="toy", num_envs=2, seed=0)
    env.reset()
    for _ in range(5):
        _, reward, *_ = env.step(torch.zeros(2, env.num_actions))
    assert reward.shape == (2,) and env.task.reference["toy"] == ROBOTS["toy"].tasks[task].reference
    env.close()


def test_a_new_hand_gets_its_ids_its_plan_recipe_and_its_table_row(toy):
    from roto.olympiad.plan import load_plan
    from roto.olympiad.results import markdown_table
    from roto.registry import gym_id

    assert gym_id("bounce", "toy") == "roto/Bounce-Toy-v0"
    variant = load_plan("benchmark").variants["ppo"]
    assert variant.agent_for("bounce", "toy")[0] == "bounce_cpu_orca"  # its record's recipe
    scores = {("bounce", robot, "blind", "ppo"): torch.ones(2).numpy() for robot in ("toy", "shadow")}
    rows = [line for line in markdown_table(scores).splitlines() if line.startswith("| ")]
    assert rows[1].startswith("| shadow") and rows[2].startswith("| toy")  # the registry's order

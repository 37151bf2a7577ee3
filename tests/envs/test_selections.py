"""The env's cached column selections (views of the CPU backend's state, made once) against the
slow reference: selections made afresh from copies of the same state, every step."""

import pytest
import torch

from roto.envs.selections import Selected
from roto.registry import list_envs, make


@pytest.mark.parametrize(("task", "robot"), list_envs())
def test_cached_selections_read_each_steps_state(task, robot):
    env = make(task, robot=robot, num_envs=3, seed=0)
    env.reset(seed=0)
    gen = torch.Generator().manual_seed(0)
    first = None
    for _ in range(40):
        action = torch.rand(3, env.num_actions, generator=gen, dtype=torch.float64) * 2 - 1
        sim = env.backend.step(action * 0.2 + env.joint_targets)
        cached = env.selections.of(sim)
        reference = env.selections.select(sim.qpos.clone(), sim.qvel.clone(), sim.sensordata.clone())
        for name, got, want in zip(Selected._fields, cached, reference, strict=True):
            if name == "taxel_force":  # only with taxel touch
                assert got is None and want is None
            else:
                assert torch.equal(got, want), name
        first = first or cached
    # the views were made once and reused (only gathered columns are made again)
    copies = env.selections.cache[4]
    for i, name in enumerate(Selected._fields[: len(env.selections.table)]):
        if i not in copies:
            assert cached[i] is first[i], name
    assert len(copies) < len(env.selections.table)
    env.close()


def test_taxel_selections_are_cached_views_too():
    env = make("bounce", robot="allegro", num_envs=2, seed=0, touch="taxels")
    env.reset(seed=0)
    sims = [env.backend.step(env.joint_targets) for _ in range(3)]
    selected = [env.selections.of(sim) for sim in sims]
    reference = env.selections.select(sims[-1].qpos.clone(), sims[-1].qvel.clone(), sims[-1].sensordata.clone())
    assert torch.equal(selected[-1].taxel_force, reference.taxel_force)
    assert selected[-1].taxel_force is selected[1].taxel_force  # a view made once
    env.close()


def test_a_backend_that_copies_gets_fresh_selections_each_step():
    env = make("bounce", robot="shadow", num_envs=2, seed=0)
    env.reset(seed=0)
    sim = env.backend.step(env.joint_targets)
    float32_sim = type(sim)(sim.qpos.float(), sim.qvel.float(), sim.sensordata.float(), sim.diverged)
    env.selections.cache = None
    env.selections.of(float32_sim)
    assert env.selections.cache is None  # converted copies are never cached
    env.close()

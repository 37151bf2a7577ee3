"""Taxel touch (``touch="taxels"``): the links' bits, then one bit per taxel of the fingertip pads
and the palm; golden scenes on every hand against MuJoCo's contacts themselves."""

import mujoco
import numpy as np
import pytest
import torch

import roto
from roto.robots import ROBOTS
from roto.sim.taxels import FINGERTIP_GRID, PALM_GRID
from tests.envs.scenes import ball_resting_on_hand

THRESHOLD = 0.01  # N, the env's default tactile_threshold


def taxels_pressed_by_contacts(model, data, names):
    """The reference: the normal force of every contact of a taxel's body whose point lies in the
    taxel's box, summed per taxel (what a touch sensor is defined to read)."""
    force = np.zeros(len(names))
    wrench = np.zeros(6)
    for c in range(data.ncon):
        contact = data.contact[c]
        mujoco.mj_contactForce(model, data, c, wrench)
        bodies = {model.geom_bodyid[contact.geom1], model.geom_bodyid[contact.geom2]}
        for k, name in enumerate(names):
            site = model.site(name)
            if site.bodyid[0] not in bodies:
                continue
            local = data.site(name).xmat.reshape(3, 3).T @ (contact.pos - data.site(name).xpos)
            if np.all(np.abs(local) <= site.size):
                force[k] += wrench[0]
    return force


@pytest.mark.parametrize("robot", ROBOTS)
def test_a_resting_ball_presses_the_taxels_under_it_and_no_others(robot):
    model, data, layout = ball_resting_on_hand(robot, "taxels")
    names = [model.sensor(i).name for i in range(model.nsensor) if model.sensor(i).name.startswith("taxel_")]
    readings = data.sensordata[layout.taxel_sensor]
    expected = taxels_pressed_by_contacts(model, data, names)
    np.testing.assert_array_equal(readings > THRESHOLD, expected > THRESHOLD)
    np.testing.assert_allclose(readings, expected, rtol=1e-6, atol=1e-9)
    palm = slice(len(readings) - PALM_GRID[0] * PALM_GRID[1], None)
    assert (readings[palm] > THRESHOLD).any()  # the ball rests on the palm
    assert (readings > THRESHOLD).sum() <= 4  # one ball presses a few taxels, not the grid


@pytest.mark.parametrize("robot", ROBOTS)
def test_taxel_touch_keeps_the_dynamics_and_the_link_bits(robot):
    envs = [roto.make("bounce", robot=robot, num_envs=2, seed=1, touch=touch) for touch in ("binary", "taxels")]
    spec = envs[0].robot
    n_links = len(spec.tactile_links)
    n_taxels = (len(spec.tip_bodies) + 1) * FINGERTIP_GRID[0] * FINGERTIP_GRID[1] + PALM_GRID[0] * PALM_GRID[1]
    assert envs[1].frame_sizes["tactile"] == n_links + n_taxels
    obs = [env.reset()[0] for env in envs]
    assert not obs[1]["tactile"].any()  # the ball starts in the air and the hand touches nothing
    gen = torch.Generator().manual_seed(0)
    lit = 0.0
    for _ in range(60):
        action = torch.rand(2, envs[0].num_actions, generator=gen) * 2 - 1
        binary, taxels = (env.step(action)[0]["tactile"] for env in envs)
        frames = taxels.unflatten(1, (envs[1].config.frame_stack, -1))
        assert torch.equal(frames[..., :n_links].flatten(1), binary)
        lit += float(frames[..., n_links:].sum())
    assert np.array_equal(envs[0].backend.physics_state(), envs[1].backend.physics_state())
    assert lit > 0
    for env in envs:
        env.close()

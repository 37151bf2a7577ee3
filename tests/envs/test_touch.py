"""Force touch (``touch="force"``): same dynamics as binary touch, golden scenes on every hand."""

import math

import numpy as np
import pytest
import torch

import roto
from roto.envs.observations import FORCE_SCALE, touch_force
from roto.robots import ROBOTS
from roto.tasks.bounce import BALL
from tests.envs.scenes import ball_resting_on_hand

GRAVITY = 9.81


def test_touch_force_is_log_of_the_force_magnitude():
    force = torch.tensor([[[0.0, 0.0, 0.0], [3.0, 4.0, 0.0], [0.0, 0.0, -0.1]]], dtype=torch.float64)
    got = touch_force(force)
    assert got.dtype == torch.float32 and got.shape == (1, 3)
    expected = torch.tensor([[0.0, math.log1p(5.0 / FORCE_SCALE), math.log(2.0)]])
    torch.testing.assert_close(got, expected)


def test_an_unknown_touch_mode_names_the_valid_ones():
    with pytest.raises(ValueError, match=r"unknown touch 'taxel'; valid touch modes: \['binary', 'force', 'taxels'\]"):
        roto.make("bounce", touch="taxel")


@pytest.mark.parametrize("robot", ROBOTS)
def test_force_touch_changes_no_dynamics_and_reads_zero_at_a_start(robot):
    envs = [roto.make("bounce", robot=robot, num_envs=3, seed=2, touch=touch) for touch in ("binary", "force")]
    obs = [env.reset()[0] for env in envs]
    assert torch.equal(obs[1]["tactile"], torch.zeros_like(obs[1]["tactile"]))  # the ball starts in the air
    gen = torch.Generator().manual_seed(0)
    touched = 0.0
    for _ in range(80):
        action = torch.rand(3, envs[0].num_actions, generator=gen) * 2 - 1
        steps = [env.step(action) for env in envs]
        assert torch.equal(steps[0][0]["proprio"], steps[1][0]["proprio"])
        assert torch.equal(steps[0][1], steps[1][1])  # rewards
        assert torch.equal(steps[0][2], steps[1][2])  # terminations
        assert steps[1][0]["tactile"].shape == steps[0][0]["tactile"].shape
        assert (steps[1][0]["tactile"] >= 0).all()
        touched += float(steps[1][0]["tactile"].sum())
    assert np.array_equal(envs[0].backend.physics_state(), envs[1].backend.physics_state())
    assert touched > 0
    for env in envs:
        env.close()


@pytest.mark.parametrize("robot", ROBOTS)
def test_a_ball_resting_on_the_hand_reads_its_weight(robot):
    _, data, layout = ball_resting_on_hand(robot, "force", seconds=4.0)
    ball_speed = np.linalg.norm(data.qvel[layout.ball_qvel[0] : layout.ball_qvel[0] + 3])
    assert ball_speed < 1e-3  # at rest
    forces = np.stack([data.sensordata[a + 1 : a + 4] for a in layout.tactile_sensor])  # (n_links, 3) net forces
    weight = BALL.mass * GRAVITY
    assert abs(np.linalg.norm(forces.sum(axis=0)) - weight) < 0.1 * weight
    touched = np.linalg.norm(forces, axis=1) > 0
    assert 0 < touched.sum() < len(forces)  # the links under the ball read force, the others none


def test_the_force_observation_is_the_force_sensors_reading():
    env = roto.make("bounce", robot="allegro", num_envs=1, touch="force", frame_stack=1)
    env.reset(seed=0)
    hold = env.hold_action()
    for _ in range(150):  # the ball lands on the held hand and stays
        obs, *_ = env.step(hold)
    sensors = torch.from_numpy(env.backend.sensordata[:, -1])
    idx = torch.from_numpy(env.layout.tactile_sensor)[:, None] + 1 + torch.arange(3)
    expected = torch.log1p(torch.linalg.vector_norm(sensors[:, idx], dim=-1) / FORCE_SCALE).float()
    assert torch.equal(obs["tactile"], expected)
    assert obs["tactile"].sum() > 0
    env.close()

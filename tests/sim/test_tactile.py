import mujoco
import numpy as np
import pytest
import torch

from roto.envs.observations import tactile_bits
from roto.robots import ROBOTS, get_robot
from roto.sim.scene import BallSpec, build_scene
from tests.conftest import make_env


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_ball_on_palm_lights_only_the_palm_bit(name):
    robot = get_robot(name)
    model, layout = build_scene(robot, (BallSpec(name="ball", radius=0.02, mass=0.03),))
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0  # the model's zero pose: fingers out, nothing near the palm centre
    data.qpos[layout.ball_qpos[0] : layout.ball_qpos[0] + 3] = [-0.01, 0.0, 0.021]  # on the palm
    data.ctrl[:] = model.qpos0[layout.act_qpos]
    mujoco.mj_step(model, data, nstep=60)
    force = torch.from_numpy(data.sensordata[layout.tactile_sensor + 1][None])
    bits = tactile_bits(force, 0.01)[0]
    palm = next(i for i, link in enumerate(robot.tactile_links) if link.endswith("palm"))
    assert bits[palm] == 1 and bits.sum() == 1, bits
    if robot.palm_tilt == (0.0, 0.0):  # on a level palm, it reads the ball's weight
        assert abs(force[0, palm] - 0.03 * 9.81) < 0.01


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_bits_clear_within_one_step_after_the_ball_leaves(name):
    env = make_env("baoding", robot=name, num_envs=1)
    n_links = len(env.robot.tactile_links)
    obs, _ = env.reset()
    for _ in range(30):
        obs, *_ = env.step(torch.zeros(1, env.num_actions))
    hold = env.hold_action()
    env.reset()
    for _ in range(30):
        obs, *_ = env.step(hold)
    assert obs["tactile"][0, -n_links:].sum() > 0
    # lift both balls 30 cm above the hand
    qpos = torch.from_numpy(env.backend.qpos.copy())
    qpos[0, env.indices.ball_pos.index[:, 2]] = 0.3
    env.backend.set_state(torch.tensor([0]), qpos, torch.zeros(1, env.model.nv))
    obs, *_ = env.step(hold)
    assert obs["tactile"][0, -n_links:].sum() == 0
    assert np.isfinite(obs["proprio"].numpy()).all()

import mujoco
import numpy as np
import torch

from roto.envs.observations import tactile_bits
from roto.robots import get_robot
from roto.sim.scene import BallSpec, build_scene
from tests.conftest import make_env

SHADOW = get_robot("shadow")


def test_ball_on_palm_lights_only_the_palm_bit():
    model, layout = build_scene(SHADOW, (BallSpec(name="ball", radius=0.02, mass=0.03),))
    data = mujoco.MjData(model)
    data.qpos[layout.ball_qpos[0] : layout.ball_qpos[0] + 3] = [-0.01, 0.0, 0.021]  # flat hand, on the palm
    mujoco.mj_step(model, data, nstep=60)
    force = torch.from_numpy(data.sensordata[layout.tactile_sensor + 1][None])
    bits = tactile_bits(force, 0.01)[0]
    palm = SHADOW.tactile_links.index("robot0:palm")
    assert bits[palm] == 1 and bits.sum() == 1, bits
    # the palm reads the ball's weight
    assert abs(force[0, palm] - 0.03 * 9.81) < 0.01


def test_bits_clear_within_one_step_after_the_ball_leaves():
    env = make_env("baoding", num_envs=1)
    obs, _ = env.reset()
    for _ in range(30):
        obs, *_ = env.step(torch.zeros(1, 20) + 0.0)
    hold = torch.from_numpy(
        2
        * (env._idx.default_qpos[0, env._idx.act_qpos].numpy() - env._idx.ctrl_lo.numpy())
        / (env._idx.ctrl_hi - env._idx.ctrl_lo).numpy()
        - 1
    ).float()[None]
    env.reset()
    for _ in range(30):
        obs, *_ = env.step(hold)
    assert obs["tactile"][0, -17:].sum() > 0
    # lift both balls 30 cm above the hand
    qpos = torch.from_numpy(env.backend.qpos.copy())
    qpos[0, env._idx.ball_pos[:, 2]] = 0.3
    env.backend.set_state(torch.tensor([0]), qpos, torch.zeros(1, env.model.nv), env._target)
    obs, *_ = env.step(hold)
    assert obs["tactile"][0, -17:].sum() == 0
    assert np.isfinite(obs["proprio"].numpy()).all()

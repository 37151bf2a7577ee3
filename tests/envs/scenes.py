"""Scripted scenes shared by the touch tests."""

import mujoco

from roto.robots import get_robot
from roto.sim.scene import build_scene
from roto.tasks.bounce import BALL


def ball_resting_on_hand(robot_name: str, touch: str, seconds: float = 3.0):
    """(model, data, layout): a Bounce ball let down onto the hand held at its default pose and
    left ``seconds`` to come to rest, with ``touch``'s sensors; sensors evaluated at the end."""
    model, layout = build_scene(get_robot(robot_name), (BALL,), touch=touch)
    data = mujoco.MjData(model)
    data.qpos[:] = layout.default_qpos
    adr = layout.ball_qpos[0]
    data.qpos[adr : adr + 3] = [0.0, 0.0, BALL.radius + 0.005]
    data.ctrl[:] = data.qpos[layout.act_qpos]
    mujoco.mj_step(model, data, nstep=int(seconds / model.opt.timestep))
    mujoco.mj_forward(model, data)
    return model, data, layout

"""Every registered hand against docs/spec.md §3's table, and the checks each hand must pass."""

import mujoco
import numpy as np
import pytest

import roto
from roto.robots import ROBOTS, get_robot
from roto.robots.mjspec_tools import palm_frame, tilt_rotation
from roto.sim.scene import build_scene
from roto.tasks.baoding import geometry_of, rest_after_drop

# docs/spec.md §3: hand joints, actions, tactile links, blind frame size
TABLE = {
    "shadow": (24, 20, 17, 97),
    "shadow_lite": (16, 13, 14, 72),
    "orca": (17, 17, 17, 85),
    "allegro": (16, 16, 20, 84),
}


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_sizes_follow_the_spec_table(name):
    joints, actions, links, frame = TABLE[name]
    robot = get_robot(name)
    model, layout = build_scene(robot, ())
    assert model.njnt == joints and model.nu == actions == robot.num_actions
    assert len(robot.tactile_links) == len(layout.tactile_sensor) == links
    env = roto.make("bounce", robot=name, num_envs=1)
    assert sum(env.frame_sizes.values()) == frame
    obs, _ = env.reset(seed=0)
    assert sum(v.shape[-1] for v in obs.values()) == 4 * frame


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_palm_frame_is_the_task_frame_up_to_the_hand_tilt(name):

    robot = get_robot(name)
    model, _ = build_scene(robot, ())
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    centre, rot = palm_frame(model, data, robot)
    np.testing.assert_allclose(centre, 0.0, atol=1e-6)
    np.testing.assert_allclose(rot.T, tilt_rotation(*robot.palm_tilt), atol=1e-6)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_no_tactile_bit_without_objects_in_the_default_pose(name):
    # (Away from it, adjacent fingers can really touch: the Shadow model pairs neighbouring
    # proximal phalanges, and such touches count, as in roto.)
    robot = get_robot(name)
    model, layout = build_scene(robot, ())
    data = mujoco.MjData(model)
    data.qpos[:] = layout.default_qpos
    data.ctrl[:] = layout.default_qpos[layout.act_qpos]
    mujoco.mj_step(model, data, nstep=240)
    assert np.all(data.sensordata[layout.tactile_sensor + 1] <= 0.01), data.sensordata[layout.tactile_sensor]


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_baoding_palm_target_is_where_the_dropped_ball_a_comes_to_rest(name):
    robot = get_robot(name)
    rest = rest_after_drop(robot)
    np.testing.assert_allclose(rest[0], np.array(geometry_of(robot).targets[0]), atol=2e-3)
    gap = np.linalg.norm(np.subtract(*geometry_of(robot).targets))
    assert gap >= 2 * geometry_of(robot).ball_radius  # balls on their targets never overlap


def test_shadow_lite_is_the_shadow_cut_down():
    lite = get_robot("shadow_lite")
    model, _ = build_scene(lite, ())
    names = {model.joint(j).name for j in range(model.njnt)}
    assert not any(("LF" in n) or ("WRJ" in n) or n.endswith("THJ2") for n in names)
    assert geometry_of(lite).ball_radius == pytest.approx(0.5 * 1.2 * 0.0254)
    # distal joints follow their middle joints 1:1 through the tendon
    data = mujoco.MjData(model)
    idx = [model.joint(f"robot0:FFJ{k}").qposadr[0] for k in (1, 0)]
    data.ctrl[lite.actuated_joints.index("robot0:FFJ1")] = 1.0
    mujoco.mj_step(model, data, nstep=480)
    assert data.qpos[idx[0]] > 0.8
    assert data.qpos[idx[1]] == pytest.approx(data.qpos[idx[0]], abs=0.03)  # tendon slack ±0.025 rad

import mujoco
import numpy as np
import pytest

from roto.robots import get_robot
from roto.robots.mjspec_tools import palm_frame
from roto.sim.scene import BallSpec, build_scene
from roto.tasks.baoding import geometry_of

SHADOW = get_robot("shadow")


def test_counts_and_names_exist_in_the_model():
    model, layout = build_scene(SHADOW, ())
    assert model.njnt == 24 and model.nu == 20
    assert len(SHADOW.actuated_joints) == 20 and len(SHADOW.tactile_links) == 17
    for link in SHADOW.tactile_links:
        assert model.body(link).id > 0
    assert len(layout.tactile_sensor) == 17


def test_palm_up_fingers_along_x_palm_centre_at_origin():
    model, _ = build_scene(SHADOW, ())
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    centre, rot = palm_frame(model, data, SHADOW)
    np.testing.assert_allclose(centre, 0.0, atol=1e-6)
    np.testing.assert_allclose(rot, np.eye(3), atol=1e-6)
    # flexing a finger moves its tip towards +z (palm side)
    tip = data.body("robot0:ffdistal").xpos.copy()
    data.qpos[model.joint("robot0:FFJ2").qposadr[0]] = 1.0
    mujoco.mj_kinematics(model, data)
    assert data.body("robot0:ffdistal").xpos[2] > tip[2] + 0.03


def test_damping_lives_in_the_actuators_and_links_are_gravity_compensated():
    model, _ = build_scene(SHADOW, ())
    assert np.all(model.dof_damping == 0.0)
    wrist = model.actuator("robot0:A_WRJ0")
    assert wrist.gainprm[0] == 5.0 and wrist.biasprm[1] == -5.0 and wrist.biasprm[2] == -0.5
    finger = model.actuator("robot0:A_FFJ2")
    assert finger.gainprm[0] == 1.0 and finger.biasprm[2] == -0.1
    assert np.all(model.body_gravcomp[1:] == 1.0)


def test_no_tactile_bit_in_the_default_pose_without_objects():
    model, layout = build_scene(SHADOW, ())
    data = mujoco.MjData(model)
    data.qpos[:] = layout.default_qpos
    data.ctrl[:] = layout.default_qpos[layout.act_qpos]
    mujoco.mj_step(model, data, nstep=240)
    assert np.all(data.sensordata[layout.tactile_sensor] == 0)


def test_baoding_targets_are_roto_s_diagonal_stack():
    """T_diag = T_palm + δ·(1, 1, 1), δ = 2r/√3 + 1 mm: one target 23 mm above the other."""
    t_palm, t_diag = np.array(geometry_of(SHADOW).targets)
    delta = 2 * geometry_of(SHADOW).ball_radius / np.sqrt(3) + 0.001
    np.testing.assert_allclose(t_diag - t_palm, delta * np.ones(3), atol=1e-12)
    assert t_diag[2] - t_palm[2] == pytest.approx(0.0230, abs=1e-4)


def test_unknown_robot_names_the_valid_ones():
    with pytest.raises(ValueError, match=r"unknown robot 'leap'.*shadow"):
        get_robot("leap")


def test_ball_spec_is_placed_in_scene():
    model, layout = build_scene(SHADOW, (BallSpec(name="b", radius=0.02, mass=0.05),))
    assert model.geom("b_geom").size[0] == pytest.approx(0.02)
    assert len(layout.ball_qpos) == 1

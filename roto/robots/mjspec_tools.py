"""Shared MjSpec helpers that turn a hand model into roto's conventions.

Every hand goes through the same steps: damping moved into the actuators, gravity compensation on
the links, position-actuator gains set, its own sensors removed, and the whole hand re-posed so
that the palm faces +z, the fingers point along +x and the palm's top-surface centre sits at the
origin of the task frame.
"""

from __future__ import annotations

import mujoco
import numpy as np

from roto.robots.spec import RobotSpec


def strip_sensors_and_keys(spec: mujoco.MjSpec) -> None:
    """Delete every sensor and keyframe a source model brings; roto adds its own."""
    for sensor in list(spec.sensors):
        spec.delete(sensor)
    for key in list(spec.keys):
        spec.delete(key)


def apply_gains(spec: mujoco.MjSpec, robot: RobotSpec) -> None:
    """Put the damping inside the position actuators and zero the joints' passive damping.

    Passive joint damping sits outside the actuator force clamp and caps joint speed at
    effort/damping; PhysX clamps the whole PD force, which is what ``kv`` in the actuator does.
    """
    for joint in spec.joints:
        joint.damping = np.zeros_like(np.asarray(joint.damping))
    by_joint = {act.target: act for act in spec.actuators}
    for name in robot.actuated_joints:
        if name not in by_joint:
            raise ValueError(f"robot {robot.name!r}: actuated joint {name!r} has no actuator in the model")
        gains = robot.gains_for(name)
        act = by_joint[name]
        gainprm = np.zeros(10)
        gainprm[0] = gains.kp
        biasprm = np.zeros(10)
        biasprm[1] = -gains.kp
        biasprm[2] = -gains.kv
        act.gainprm = gainprm
        act.biasprm = biasprm
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    order = {name: i for i, name in enumerate(robot.actuated_joints)}
    extra = [act.target for act in spec.actuators if act.target not in order]
    if extra:
        raise ValueError(f"robot {robot.name!r}: actuators on joints not listed as actuated: {extra}")


def enable_gravity_compensation(body: mujoco.MjsBody) -> None:
    """Set full gravity compensation on ``body`` and all its descendants (roto disables link gravity)."""
    body.gravcomp = 1.0
    for child in body.bodies:
        enable_gravity_compensation(child)


def _rotation_from_rows(f: np.ndarray, lateral: np.ndarray) -> np.ndarray:
    """Rotation whose rows are (finger, -lateral, normal), Gram-Schmidt orthonormalised."""
    f = f / np.linalg.norm(f)
    lateral = lateral - f * (lateral @ f)
    lateral = lateral / np.linalg.norm(lateral)
    normal = np.cross(lateral, f)
    return np.stack([f, -lateral, normal])


def palm_frame(model: mujoco.MjModel, data: mujoco.MjData, robot: RobotSpec) -> tuple[np.ndarray, np.ndarray]:
    """World pose of the palm frame at the current state: (centre (3,), rotation rows (3, 3)).

    Finger direction f = mean(tips) - mean(knuckles); lateral l = first knuckle - last knuckle;
    normal n = l x f. The centre is the palm geom's centre pushed to its top face along n.
    """
    knuckles = np.array([data.body(b).xpos for b in robot.knuckle_bodies])
    tips = np.array([data.body(b).xpos for b in robot.tip_bodies])
    rot = _rotation_from_rows(tips.mean(0) - knuckles.mean(0), knuckles[0] - knuckles[-1])
    geom = model.geom(robot.palm_geom)
    centre = data.geom(robot.palm_geom).xpos.copy()
    geom_rot = data.geom(robot.palm_geom).xmat.reshape(3, 3)
    # Half-thickness of the palm geom along the palm normal (box: sum of projected half-sizes).
    normal_local = geom_rot.T @ rot[2]
    half = float(np.abs(normal_local) @ geom.size) if geom.type[0] == mujoco.mjtGeom.mjGEOM_BOX else geom.size[0]
    return centre + half * rot[2], rot


def pose_root_in_task_frame(spec: mujoco.MjSpec, robot: RobotSpec) -> None:
    """Move the hand's root body so that, at zero joint angles, the palm frame equals the task frame."""
    root = spec.body(robot.root_body)
    root.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT  # an euler/axisangle would override quat
    root.pos = np.zeros(3)
    root.quat = np.array([1.0, 0.0, 0.0, 0.0])
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    centre_w, rot_w = palm_frame(model, data, robot)
    # Root is at the world origin with identity orientation, so world = root frame here.
    tilt = tilt_rotation(*robot.palm_tilt)
    rotation = tilt @ rot_w
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, rotation.flatten())
    root.quat = quat
    root.pos = -rotation @ centre_w


def tilt_rotation(about_x: float, about_y: float) -> np.ndarray:
    """R_y(about_y) @ R_x(about_x): positive about_y lowers +x, positive about_x lowers -y."""
    cx, sx = np.cos(about_x), np.sin(about_x)
    cy, sy = np.cos(about_y), np.sin(about_y)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cx, -sx], [0.0, sx, cx]])
    ry = np.array([[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]])
    return ry @ rx


def add_exclusions(spec: mujoco.MjSpec, robot: RobotSpec) -> None:
    """Filter the contact pairs the robot lists (e.g. palm against knuckles on a welded palm)."""
    for body1, body2 in robot.excluded_contacts:
        exclude = spec.add_exclude()
        exclude.bodyname1 = body1
        exclude.bodyname2 = body2


def build_hand(robot: RobotSpec) -> mujoco.MjSpec:
    """The hand in roto's conventions, ready for a task to add its objects."""
    spec = robot.load_spec()
    strip_sensors_and_keys(spec)
    apply_gains(spec, robot)
    enable_gravity_compensation(spec.body(robot.root_body))
    add_exclusions(spec, robot)
    pose_root_in_task_frame(spec, robot)
    return spec

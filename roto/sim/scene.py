"""Compose a hand and a task's balls into one MuJoCo model, and index what the env reads.

The model holds, besides the hand, one free-floating sphere per ball and two kinds of
``contact`` sensors (MuJoCo 4's exact per-body contact sensors):

* one per tactile link: ``body1 = link``, any partner, data ``found force``; for binary touch
  reduced to the strongest contact, so the first force component is that contact's normal force;
  for force touch reduced to the net force of all the link's contacts (global frame);
* one per ball: ``body1 = ball``, ``subtree2 = hand root`` (hand contact only, not ball-ball);
* one for the hand's self-contacts: ``subtree1 = subtree2 = hand root``, data ``found dist``
  reduced to the deepest contact, which the env uses to keep interpenetrating poses out of
  episode starts;
* one per ball for its clearance: ``body1 = ball``, any partner (the hand or another ball), data
  ``found dist`` reduced to the deepest contact, which keeps balls started inside the hand or
  inside each other out of episode starts.

With taxel touch, a ``touch`` sensor on each taxel box over the fingertip pads and the palm
(``roto.sim.taxels``).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from roto.robots.mjspec_tools import build_hand
from roto.robots.spec import RobotSpec
from roto.sim.taxels import FINGERTIP_GRID, PALM_GRID, Taxel, pad_grid

PHYSICS_DT = 1.0 / 240.0
"""Physics timestep (s), docs/spec.md §1."""

_FOUND, _FORCE, _DIST = 1, 2, 8
_REDUCE_MINDIST, _REDUCE_MAXFORCE, _REDUCE_NETFORCE = 1, 2, 3
TAXEL_SITE_GROUP = 5
"""Site group of the taxel boxes (not drawn by default)."""
CONTACT_SENSOR_DIM = 4
"""Values per contact sensor: (number of contacts found, force in the contact frame (3,))."""


@dataclass(frozen=True, kw_only=True)
class BallSpec:
    """A free sphere in the scene (radius m, mass kg, sliding friction)."""

    name: str
    radius: float
    mass: float
    friction: float = 1.0
    rgba: tuple[float, float, float, float] = (0.9, 0.3, 0.2, 1.0)


@dataclass(frozen=True, kw_only=True)
class SceneLayout:
    """Where each quantity the env needs lives in qpos / qvel / ctrl / sensordata.

    All index arrays are int64 numpy arrays; lengths are given in brackets.
    """

    act_qpos: np.ndarray  # [n_act] qpos address of each actuated joint (action order)
    obs_qpos: np.ndarray  # [n_obs] qpos address of each observed joint
    obs_qvel: np.ndarray  # [n_obs] dof address of each observed joint
    obs_lo: np.ndarray  # [n_obs] lower limit of each observed joint
    obs_hi: np.ndarray  # [n_obs] upper limit
    ctrl_lo: np.ndarray  # [n_act] lower joint limit of each actuated joint (= actuator ctrlrange)
    ctrl_hi: np.ndarray  # [n_act] upper joint limit
    ball_qpos: np.ndarray  # [n_ball] qpos address of each ball's free joint (position xyz, quat wxyz)
    ball_qvel: np.ndarray  # [n_ball] dof address of each ball's free joint (linear xyz, angular xyz)
    tactile_sensor: np.ndarray  # [n_tactile] sensordata address of each link's contact sensor
    taxel_sensor: np.ndarray  # [n_taxels] sensordata address of each taxel's touch sensor (none without taxels)
    self_contact_sensor: int  # sensordata address of the hand's self-contact sensor (found, dist)
    ball_contact_sensor: np.ndarray  # [n_ball] sensordata address of each ball-hand contact sensor
    ball_clearance_sensor: np.ndarray  # [n_ball] sensordata address of each ball's deepest contact (found, dist)
    default_qpos: np.ndarray  # [nq] hand at its default pose, balls at the origin (placed by the task)
    hand_qpos: np.ndarray  # [n_hand_q] qpos addresses of every hand joint


def _add_contact_sensor(
    spec: mujoco.MjSpec, name: str, body: str, subtree2: str | None = None, reduce: int = _REDUCE_MAXFORCE
) -> None:
    sensor = spec.add_sensor()
    sensor.name = name
    sensor.type = mujoco.mjtSensor.mjSENS_CONTACT
    sensor.objtype = mujoco.mjtObj.mjOBJ_BODY
    sensor.objname = body
    if subtree2 is not None:
        sensor.reftype = mujoco.mjtObj.mjOBJ_XBODY
        sensor.refname = subtree2
    sensor.intprm = np.array([_FOUND | _FORCE, reduce, 1] + [0] * (len(sensor.intprm) - 3))


def _add_deepest_contact_sensor(spec: mujoco.MjSpec, name: str, body: str, subtree: str | None = None) -> None:
    """(found, dist) of the deepest contact of ``body`` (or of the subtree ``subtree`` against itself)."""
    sensor = spec.add_sensor()
    sensor.name = name
    sensor.type = mujoco.mjtSensor.mjSENS_CONTACT
    if subtree is None:
        sensor.objtype = mujoco.mjtObj.mjOBJ_BODY
        sensor.objname = body
    else:
        sensor.objtype = sensor.reftype = mujoco.mjtObj.mjOBJ_XBODY
        sensor.objname = sensor.refname = subtree
    sensor.intprm = np.array([_FOUND | _DIST, _REDUCE_MINDIST, 1] + [0] * (len(sensor.intprm) - 3))


def build_scene_spec(robot: RobotSpec, balls: tuple[BallSpec, ...], touch: str = "binary") -> mujoco.MjSpec:
    """The hand (posed in the task frame) plus the balls and roto's sensors, as an MjSpec; ``touch``
    (``binary``, ``force`` or ``taxels``) chooses what the tactile links' sensors reduce their
    contacts to, and whether the fingertips and the palm carry taxels."""
    spec = build_hand(robot)
    spec.modelname = f"roto_{robot.name}_{len(balls)}balls"
    spec.option.timestep = PHYSICS_DT
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = np.array([0.0, 0.0, -9.81])
    for ball in balls:
        body = spec.worldbody.add_body(name=ball.name, pos=[0.0, 0.0, 0.3])
        body.add_freejoint(name=f"{ball.name}_free")
        body.add_geom(
            name=f"{ball.name}_geom",
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[ball.radius, 0.0, 0.0],
            mass=ball.mass,
            friction=[ball.friction, 0.005, 0.0001],
            contype=1,
            conaffinity=1,
            condim=3,
            rgba=list(ball.rgba),
        )
    reduce = _REDUCE_NETFORCE if touch == "force" else _REDUCE_MAXFORCE
    for link in robot.tactile_links:
        _add_contact_sensor(spec, f"touch_{link}", link, reduce=reduce)
    for ball in balls:
        _add_contact_sensor(spec, f"hand_contact_{ball.name}", ball.name, subtree2=robot.root_body)
    _add_deepest_contact_sensor(spec, "hand_self_contact", robot.root_body, subtree=robot.root_body)
    for ball in balls:
        _add_deepest_contact_sensor(spec, f"clearance_{ball.name}", ball.name)
    if touch == "taxels":
        for k, taxel in enumerate(hand_taxels(robot)):
            _add_taxel(spec, f"taxel_{k}", taxel)
    return spec


def hand_taxels(robot: RobotSpec) -> list[Taxel]:
    """The hand's taxels, in observation order: each fingertip (``tip_bodies``, then the thumb's),
    then the palm (``roto.sim.taxels``), laid out at the default pose in the task frame."""
    model = build_hand(robot).compile()
    data = mujoco.MjData(model)
    data.qpos[:] = default_pose_qpos(model, robot)
    mujoco.mj_kinematics(model, data)
    above_palm = np.array([0.0, 0.0, 0.05])  # task frame: palm centre at the origin, z up
    taxels = []
    for tip in (*robot.tip_bodies, robot.thumb_tip):
        taxels += pad_grid(model, data, tip, above_palm - data.body(tip).xpos, FINGERTIP_GRID)
    palm = model.body(model.geom(robot.palm_geom).bodyid[0]).name
    return taxels + pad_grid(model, data, palm, np.array([0.0, 0.0, 1.0]), PALM_GRID)


def default_pose_qpos(model: mujoco.MjModel, robot: RobotSpec) -> np.ndarray:
    """(nq,) the model's reference qpos with the hand's joints at ``robot.default_pose``."""
    qpos = model.qpos0.copy()
    for joint, angle in robot.default_pose.items():
        qpos[model.joint(joint).qposadr[0]] = angle
    return qpos


def _add_taxel(spec: mujoco.MjSpec, name: str, taxel: Taxel) -> None:
    site = spec.body(taxel.body).add_site()
    site.name = name
    site.type = mujoco.mjtGeom.mjGEOM_BOX
    site.pos = taxel.pos
    site.size = taxel.half_size
    site.group = TAXEL_SITE_GROUP
    sensor = spec.add_sensor()
    sensor.name = name
    sensor.type = mujoco.mjtSensor.mjSENS_TOUCH
    sensor.objtype = mujoco.mjtObj.mjOBJ_SITE
    sensor.objname = name


def scene_layout(model: mujoco.MjModel, robot: RobotSpec, balls: tuple[BallSpec, ...]) -> SceneLayout:
    """Index the compiled scene (see ``SceneLayout``)."""

    def joint_ids(names: tuple[str, ...]) -> np.ndarray:
        return np.array([model.joint(n).id for n in names], dtype=np.int64)

    act = joint_ids(robot.actuated_joints)
    obs = joint_ids(robot.observed_joints)
    ball_joints = np.array([model.joint(f"{b.name}_free").id for b in balls], dtype=np.int64)
    ball_ids = {model.joint(j).id for j in (f"{b.name}_free" for b in balls)}
    hand_joints = np.array([j for j in range(model.njnt) if j not in ball_ids], dtype=np.int64)
    act_order = [int(i) for j in act for i in np.flatnonzero(model.actuator_trnid[:, 0] == j)]
    if act_order != list(range(model.nu)):
        raise ValueError(f"robot {robot.name!r}: actuator order must follow actuated_joints, got {act_order}")

    default_qpos = default_pose_qpos(model, robot)

    def sensor_adr(name: str) -> int:
        return int(model.sensor_adr[model.sensor(name).id])

    return SceneLayout(
        act_qpos=model.jnt_qposadr[act].astype(np.int64),
        obs_qpos=model.jnt_qposadr[obs].astype(np.int64),
        obs_qvel=model.jnt_dofadr[obs].astype(np.int64),
        obs_lo=model.jnt_range[obs, 0].copy(),
        obs_hi=model.jnt_range[obs, 1].copy(),
        ctrl_lo=model.jnt_range[act, 0].copy(),
        ctrl_hi=model.jnt_range[act, 1].copy(),
        ball_qpos=model.jnt_qposadr[ball_joints].astype(np.int64),
        ball_qvel=model.jnt_dofadr[ball_joints].astype(np.int64),
        tactile_sensor=np.array([sensor_adr(f"touch_{link}") for link in robot.tactile_links], dtype=np.int64),
        ball_contact_sensor=np.array([sensor_adr(f"hand_contact_{b.name}") for b in balls], dtype=np.int64),
        self_contact_sensor=sensor_adr("hand_self_contact"),
        ball_clearance_sensor=np.array([sensor_adr(f"clearance_{b.name}") for b in balls], dtype=np.int64),
        taxel_sensor=np.array(
            [model.sensor_adr[i] for i in range(model.nsensor) if model.sensor(i).name.startswith("taxel_")],
            dtype=np.int64,
        ),
        default_qpos=default_qpos,
        hand_qpos=model.jnt_qposadr[hand_joints].astype(np.int64),
    )


def build_scene(
    robot: RobotSpec, balls: tuple[BallSpec, ...], touch: str = "binary"
) -> tuple[mujoco.MjModel, SceneLayout]:
    """Compile the scene and index it."""
    model = build_scene_spec(robot, balls, touch).compile()
    return model, scene_layout(model, robot, balls)

"""Allegro Hand (16 joints, all actuated): roto's own model, built with MjSpec from public facts.

No clean PyPI package carries an Allegro model, so roto builds one from the published
kinematics and collision primitives of the Wonik Allegro Hand v4 (right): link lengths, joint axes
and ranges, link masses and the box/capsule collision set (sources in docs/robots.md). Collision
only, no meshes: every link is drawn by its collision primitive.

Frames follow the Allegro description: fingers extend along +z from the top of the palm, they flex
towards +x (the palm side), the index finger is on +y.
"""

from __future__ import annotations

import math
from types import MappingProxyType

import mujoco
import numpy as np

from roto.robots.spec import BaodingGeometry, BounceScript, Gains, PairRecord, RobotSpec, side_by_side

_BAODING_RADIUS = 0.5 * 2.0 * 0.0254

# Finger chain (index, middle, ring): base (abduction about z) -> proximal -> medial -> distal -> tip,
# each joint this far along z from the previous one (m).
FINGER_BASES = {  # name: (position on the palm (m), tilt about x (rad))
    "ff": ((0.0, 0.0435, -0.001542), math.radians(-5.0)),
    "mf": ((0.0, 0.0, 0.0007), 0.0),
    "rf": ((0.0, -0.0435, -0.001542), math.radians(5.0)),
}
LINK_OFFSETS = {"proximal": 0.0164, "medial": 0.054, "distal": 0.0384}
FINGER_RANGES = {
    "base": (-0.47, 0.47),
    "proximal": (-0.196, 1.61),
    "medial": (-0.174, 1.709),
    "distal": (-0.227, 1.618),
}
FINGER_MASSES = {"base": 0.0119, "proximal": 0.065, "medial": 0.0355, "distal": 0.0096, "tip": 0.0168}
# Collision boxes: half-sizes (thickness x, width y, half-length z), centred half a length along z.
FINGER_BOX = {"base": 0.0082, "proximal": 0.027, "medial": 0.0192, "distal": 0.008}
LINK_HALF_THICKNESS, LINK_HALF_WIDTH = 0.0098, 0.01375
TIP_CAPSULE = (0.012, 0.010, 0.019)  # radius, half-length, position along z in the distal frame

PALM_MASS = 0.4154
PALM_BOX = ((0.0204, 0.0565, 0.0475), (-0.0093, 0.0, -0.0475))  # half-sizes, centre

# Thumb: base (rotation about -x) -> proximal (about z) -> medial (about y) -> distal (about y) -> tip.
THUMB_BASE_POS = (-0.0182, 0.019333, -0.045987)
THUMB_BASE_QUAT = (0.477714, -0.521334, -0.521334, -0.477714)
THUMB_OFFSETS = {"proximal": (-0.027, 0.005, 0.0399), "medial": (0.0, 0.0, 0.0177), "distal": (0.0, 0.0, 0.0514)}
THUMB_AXES = {
    "base": (-1.0, 0.0, 0.0),
    "proximal": (0.0, 0.0, 1.0),
    "medial": (0.0, 1.0, 0.0),
    "distal": (0.0, 1.0, 0.0),
}
THUMB_RANGES = {
    "base": (0.263, 1.396),
    "proximal": (-0.105, 1.163),
    "medial": (-0.189, 1.644),
    "distal": (-0.162, 1.719),
}
THUMB_MASSES = {"base": 0.0176, "proximal": 0.0119, "medial": 0.038, "distal": 0.0388, "tip": 0.0168}
THUMB_BOXES = {  # half-sizes, centre
    "base": ((0.0179, 0.017, 0.02275), (-0.0179, 0.009, 0.0145)),
    "proximal": ((LINK_HALF_THICKNESS, LINK_HALF_WIDTH, 0.00885), (0.0, 0.0, 0.00885)),
    "medial": ((LINK_HALF_THICKNESS, LINK_HALF_WIDTH, 0.0257), (0.0, 0.0, 0.0257)),
    "distal": ((LINK_HALF_THICKNESS, LINK_HALF_WIDTH, 0.0157), (0.0, 0.0, 0.0157)),
}
THUMB_TIP_CAPSULE = (0.012, 0.008, 0.035)

EFFORT = 0.5
"""Actuator force limit (N·m), roto's Allegro effort."""
ARMATURE = 0.001
LINK_RGBA = (0.2, 0.2, 0.2, 1.0)
TIP_RGBA = (0.9, 0.9, 0.9, 1.0)


def _box(body: mujoco.MjsBody, half: tuple[float, float, float], centre: tuple[float, float, float]) -> None:
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=list(half), pos=list(centre), rgba=list(LINK_RGBA), mass=0.0)


def _tip(body: mujoco.MjsBody, capsule: tuple[float, float, float]) -> None:
    radius, half, z = capsule
    body.add_geom(
        type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[radius, half, 0.0], pos=[0.0, 0.0, z], rgba=list(TIP_RGBA), mass=0.0
    )


def _link(parent: mujoco.MjsBody, name: str, pos, quat, mass: float, joint: str, axis, limits) -> mujoco.MjsBody:
    body = parent.add_body(name=name, pos=list(pos), quat=list(quat), mass=mass)
    body.explicitinertial = True
    body.inertia = [mass * 1e-3, mass * 1e-3, mass * 1e-3]  # point-like links; armature dominates
    body.add_joint(name=joint, axis=list(axis), range=list(limits), armature=ARMATURE)
    return body


def _finger(palm: mujoco.MjsBody, finger: str) -> None:
    pos, tilt = FINGER_BASES[finger]
    quat = np.zeros(4)
    mujoco.mju_axisAngle2Quat(quat, np.array([1.0, 0.0, 0.0]), tilt)
    body = _link(
        palm, f"{finger}_base", pos, quat, FINGER_MASSES["base"], f"{finger}j0", (0, 0, 1), FINGER_RANGES["base"]
    )
    _box(body, (LINK_HALF_THICKNESS, LINK_HALF_WIDTH, FINGER_BOX["base"]), (0.0, 0.0, FINGER_BOX["base"]))
    for index, link in enumerate(("proximal", "medial", "distal"), start=1):
        body = _link(
            body,
            f"{finger}_{link}",
            (0.0, 0.0, LINK_OFFSETS[link]),
            (1, 0, 0, 0),
            FINGER_MASSES[link],
            f"{finger}j{index}",
            (0, 1, 0),
            FINGER_RANGES[link],
        )
        _box(body, (LINK_HALF_THICKNESS, LINK_HALF_WIDTH, FINGER_BOX[link]), (0.0, 0.0, FINGER_BOX[link]))
    tip = body.add_body(name=f"{finger}_tip", mass=FINGER_MASSES["tip"])
    tip.explicitinertial = True
    tip.inertia = [FINGER_MASSES["tip"] * 1e-3] * 3
    _tip(tip, TIP_CAPSULE)


def _thumb(palm: mujoco.MjsBody) -> None:
    body = _link(
        palm,
        "th_base",
        THUMB_BASE_POS,
        THUMB_BASE_QUAT,
        THUMB_MASSES["base"],
        "thj0",
        THUMB_AXES["base"],
        THUMB_RANGES["base"],
    )
    _box(body, *THUMB_BOXES["base"])
    for index, link in enumerate(("proximal", "medial", "distal"), start=1):
        body = _link(
            body,
            f"th_{link}",
            THUMB_OFFSETS[link],
            (1, 0, 0, 0),
            THUMB_MASSES[link],
            f"thj{index}",
            THUMB_AXES[link],
            THUMB_RANGES[link],
        )
        _box(body, *THUMB_BOXES[link])
    tip = body.add_body(name="th_tip", mass=THUMB_MASSES["tip"])
    tip.explicitinertial = True
    tip.inertia = [THUMB_MASSES["tip"] * 1e-3] * 3
    _tip(tip, THUMB_TIP_CAPSULE)


def load_allegro_spec() -> mujoco.MjSpec:
    """The right Allegro hand: mount -> palm -> 3 fingers + thumb, 16 hinge joints and position actuators."""
    spec = mujoco.MjSpec()
    spec.modelname = "allegro_right"
    spec.compiler.autolimits = True
    spec.compiler.degree = False  # ranges below are in radians
    mount = spec.worldbody.add_body(name="allegro_mount")
    palm = mount.add_body(name="palm", mass=PALM_MASS)
    palm.explicitinertial = True
    palm.ipos = [0.0, 0.0, -0.0475]
    palm.inertia = [1e-4, 1e-4, 1e-4]
    palm.add_geom(
        name="palm_box",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=list(PALM_BOX[0]),
        pos=list(PALM_BOX[1]),
        rgba=list(LINK_RGBA),
        mass=0.0,
    )
    for finger in FINGER_BASES:
        _finger(palm, finger)
    _thumb(palm)
    for finger in (*FINGER_BASES, "th"):
        for index in range(4):
            joint = spec.joint(f"{finger}j{index}")
            actuator = spec.add_actuator(name=f"{finger}a{index}", target=joint.name)
            actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
            actuator.ctrlrange = np.array(joint.range)
            actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            actuator.forcerange = np.array([-EFFORT, EFFORT])
            actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            actuator.set_to_position(kp=1.0)  # gains are set by roto's apply_gains
    for finger in (*FINGER_BASES, "th"):
        exclude = spec.add_exclude()
        exclude.bodyname1, exclude.bodyname2 = "palm", f"{finger}_base"
    exclude = spec.add_exclude()
    exclude.bodyname1, exclude.bodyname2 = "palm", "th_proximal"
    return spec


_ACTUATED = tuple(f"{f}j{i}" for f in ("ff", "mf", "rf", "th") for i in range(4))

# The Allegro has no wrist either: its fingers curl the ball up from the palm (j2 straightens from
# 1.23 to 0.32 while j1 rises and j3 flicks up) and the thumb swings up beside it (thj2).
ALLEGRO_BOUNCE = BounceScript(
    swing={
        **{f"{f}j1": (0.211, 0.173, 0.472) for f in ("ff", "mf", "rf")},
        **{f"{f}j2": (1.6, 1.231, 0.324) for f in ("ff", "mf", "rf")},
        **{f"{f}j3": (0.681, -0.052, 1.04) for f in ("ff", "mf", "rf")},
        "thj2": (0.674, 0.397, 1.64),
    },
    lean={f"{f}j1": (-6.244, -8.267) for f in ("ff", "mf", "rf")},
    pose={"thj0": 0.325, "thj1": 0.079},
    centre_x=-0.007,
    wind_up_steps=2,
    strike_steps=9,
    settle_speed=0.346,
)


ALLEGRO = RobotSpec(
    name="allegro",
    display_name="Allegro",
    load_spec=load_allegro_spec,
    root_body="allegro_mount",
    actuated_joints=_ACTUATED,
    observed_joints=_ACTUATED,
    # 20 = palm + 4 digits x (proximal, medial, distal, tip) + the three finger bases. The thumb's
    # base link is left out: it sits under the palm, out of reach of objects on the hand.
    tactile_links=(
        "palm",
        *(f"{f}_{link}" for f in ("ff", "mf", "rf", "th") for link in ("proximal", "medial", "distal", "tip")),
        *(f"{f}_base" for f in ("ff", "mf", "rf")),
    ),
    gains={"j": Gains(kp=3.0, kv=0.1)},
    # Cupped: fingers straight at the middle joint with their distal links bent up into a front
    # wall, thumb bent up at its tip as a side wall, the hand tilted 0.035 rad towards the fingertips
    # so the ball rolls against that wall (random search, docs/robots.md).
    default_pose={
        "thj0": 0.372,
        "thj1": -0.035,
        "thj2": -0.18,
        "thj3": 1.707,
        **{f"{f}j1": 0.33 for f in ("ff", "mf", "rf")},
        **{f"{f}j2": -0.003 for f in ("ff", "mf", "rf")},
        **{f"{f}j3": 1.219 for f in ("ff", "mf", "rf")},
    },
    palm_tilt=(0.0, 0.035),
    palm_geom="palm_box",
    knuckle_bodies=("ff_base", "mf_base", "rf_base"),
    tip_bodies=("ff_tip", "mf_tip", "rf_tip"),
    thumb_tip="th_tip",
    tasks=MappingProxyType(
        {
            "bounce": PairRecord(
                reference=11.8, warp_peaks=(23, 92), recipe="bounce_cpu_quickstart", script=ALLEGRO_BOUNCE
            ),
            "baoding": PairRecord(
                reference=5.03,
                warp_peaks=(24, 96),
                recipe="baoding_cpu",
                geometry=BaodingGeometry(
                    ball_radius=_BAODING_RADIUS,
                    # T_palm: where the dropped ball a comes to rest (rest_after_drop); roto's Allegro variant, the
                    # second target beside it, 2r + 5 mm away across the fingers (towards the index finger)
                    targets=side_by_side((0.0589, 0.0, 0.0217), _BAODING_RADIUS, (0.0, -1.0, 0.0)),
                ),
            ),
        }
    ),
)

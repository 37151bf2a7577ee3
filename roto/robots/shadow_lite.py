"""Shadow Hand Lite (16 joints, 13 actuators), derived from the gymnasium-robotics Shadow with MjSpec.

No Lite model ships on PyPI, so roto cuts the full Shadow down the way the real Lite differs from
it (docs/robots.md): no little finger, no wrist joints (the wrist is fixed, bent back 40° as on
the real Lite), and no THJ2 (the Lite's thumb has no Shadow THJ3). Each finger's distal joint is
tied 1:1 to its middle joint (the Lite's mimic joint), by re-weighting the model's coupling tendon.
Joint names keep the gym convention (J0 distal, J3 abduction).
"""

from __future__ import annotations

import math
from types import MappingProxyType

import mujoco
import numpy as np

from roto.robots.shadow import load_shadow_spec
from roto.robots.spec import BaodingGeometry, BounceScript, Gains, PairRecord, RobotSpec, diagonal_stack

_BAODING_RADIUS = 0.5 * 1.2 * 0.0254

WRIST_BENT_BACK = math.radians(40.0)
"""The Lite's fixed wrist extension (rad); WRJ0 < 0 is extension in the gym model."""

COUPLING_SLACK = np.array([-0.0002, 0.0002])
"""Range of the J0 - J1 coupling tendon (m of tendon; 0.00805 m per rad)."""

_REMOVED_JOINTS = ("WRJ1", "WRJ0", "THJ2")
_FINGERS = ("ff", "mf", "rf")


def _j(name: str) -> str:
    return f"robot0:{name}"


def _mentions_removed(name: str) -> bool:
    return "LF" in name or any(joint in name for joint in _REMOVED_JOINTS)


def load_shadow_lite_spec() -> mujoco.MjSpec:
    """The Lite as an MjSpec: 16 joints, 13 position actuators, J0 = J1 tendons."""
    spec = load_shadow_spec()
    for actuator in list(spec.actuators):
        if _mentions_removed(actuator.name):
            spec.delete(actuator)
    for tendon in list(spec.tendons):
        if _mentions_removed(tendon.name):
            spec.delete(tendon)
    for sensor in list(spec.sensors):
        spec.delete(sensor)
    spec.delete(spec.body(_j("lfmetacarpal")))
    for joint in _REMOVED_JOINTS:
        spec.delete(spec.joint(_j(joint)))
    # Fix the wrist bent back: rotate the palm about the former WRJ0 axis (its x, at its origin).
    palm = spec.body(_j("palm"))
    bend = np.zeros(4)
    mujoco.mju_axisAngle2Quat(bend, np.array([1.0, 0.0, 0.0]), -WRIST_BENT_BACK)
    quat = np.zeros(4)
    mujoco.mju_mulQuat(quat, np.asarray(palm.quat, dtype=float), bend)
    palm.quat = quat
    # The gym coupling tendon holds 0.00705·J0 - 0.00805·J1 in ±1 mm (±0.12 rad of slack); equal
    # weights and a tighter range make it J0 = J1 within ±0.025 rad.
    for finger in ("FF", "MF", "RF"):
        old = spec.tendon(_j(f"T_{finger}J1c"))
        solref, solimp = np.array(old.solref_limit), np.array(old.solimp_limit)
        spec.delete(old)
        tendon = spec.add_tendon(
            name=_j(f"T_{finger}J1c"), range=COUPLING_SLACK, solref_limit=solref, solimp_limit=solimp
        )
        tendon.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        tendon.wrap_joint(_j(f"{finger}J0"), 0.00805)
        tendon.wrap_joint(_j(f"{finger}J1"), -0.00805)
    return spec


_ACTUATED = tuple(
    _j(n)
    for n in (
        "FFJ3",
        "FFJ2",
        "FFJ1",
        "MFJ3",
        "MFJ2",
        "MFJ1",
        "RFJ3",
        "RFJ2",
        "RFJ1",
        "THJ4",
        "THJ3",
        "THJ1",
        "THJ0",
    )
)

_OBSERVED = tuple(
    _j(n)
    for n in (
        "FFJ3",
        "FFJ2",
        "FFJ1",
        "FFJ0",
        "MFJ3",
        "MFJ2",
        "MFJ1",
        "MFJ0",
        "RFJ3",
        "RFJ2",
        "RFJ1",
        "RFJ0",
        "THJ4",
        "THJ3",
        "THJ1",
        "THJ0",
    )
)

# The Lite has no wrist: its fingers extend (wind-up: the ball rolls out onto them, the hand being
# tilted towards the fingertips), then flick up at the knuckles (J2) and middle joints (J1) while
# the thumb (THJ3) swings up beside them.
SHADOW_LITE_BOUNCE = BounceScript(
    swing={
        **{f"robot0:{f}J2": (0.223, 0.033, 1.504) for f in ("FF", "MF", "RF")},
        **{f"robot0:{f}J1": (0.288, 0.0, 0.8) for f in ("FF", "MF", "RF")},
        "robot0:THJ3": (0.197, 0.298, 0.986),
    },
    lean={f"robot0:{f}J2": (1.204, -3.184) for f in ("FF", "MF", "RF")},
    pose={"robot0:THJ4": 0.665, "robot0:RFJ3": -0.31},
    centre_x=0.03,
    wind_up_steps=10,
    strike_steps=4,
    settle_speed=0.088,
)


SHADOW_LITE = RobotSpec(
    name="shadow_lite",
    display_name="ShadowLite",
    load_spec=load_shadow_lite_spec,
    root_body="robot0:hand mount",
    actuated_joints=_ACTUATED,
    observed_joints=_OBSERVED,  # docs/spec.md §3: the Lite's pos/vel cover all 16 joints
    tactile_links=tuple(_j(f"{f}distal") for f in (*_FINGERS, "th"))
    + tuple(_j(f"{f}middle") for f in (*_FINGERS, "th"))
    + tuple(_j(f"{f}proximal") for f in (*_FINGERS, "th"))
    + (_j("palm"), _j("thbase")),
    gains={"J": Gains(kp=1.0, kv=0.1)},
    # Cupped: fingers curled into a front wall, ring finger abducted outwards, thumb a side wall;
    # the hand tilted so the palm slopes down towards the fingers and the thumb, since without a
    # little finger nothing walls off that side (docs/robots.md: how it was found).
    default_pose={
        _j("FFJ2"): 0.65,
        _j("MFJ2"): 0.65,
        _j("RFJ2"): 0.65,
        _j("FFJ1"): 0.69,
        _j("MFJ1"): 0.69,
        _j("RFJ1"): 0.69,
        _j("RFJ3"): -0.34,
        _j("THJ4"): 0.72,
        _j("THJ3"): 0.29,
    },
    palm_tilt=(0.151, 0.101),
    coupled_joints={_j(f"{f}J0"): (_j(f"{f}J1"), 1.0) for f in ("FF", "MF", "RF")},
    palm_geom=_j("C_palm0"),
    knuckle_bodies=tuple(_j(f"{f}knuckle") for f in _FINGERS),
    tip_bodies=tuple(_j(f"{f}distal") for f in _FINGERS),
    thumb_tip=_j("thdistal"),
    excluded_contacts=tuple((_j("palm"), _j(b)) for b in ("ffknuckle", "mfknuckle", "rfknuckle", "thbase")),
    tasks=MappingProxyType(
        {
            "bounce": PairRecord(
                reference=9.5, warp_peaks=(8, 53), recipe="bounce_cpu_quickstart", script=SHADOW_LITE_BOUNCE
            ),
            "baoding": PairRecord(
                reference=5.5,
                warp_peaks=(9, 48),
                recipe="baoding_cpu",
                geometry=BaodingGeometry(
                    ball_radius=_BAODING_RADIUS,
                    # T_palm: where the dropped ball a comes to rest (rest_after_drop); roto's stack
                    # δ·(1, 1, 1) above it
                    targets=diagonal_stack((0.0559, -0.0106, 0.0068), _BAODING_RADIUS, (1.0, 1.0, 1.0)),
                    # above the finger pocket: dropped above the palm centre, 12 of 12 pairs fell off
                    # (docs/tasks.md)
                    drop_centre=(0.041, -0.014, 0.09),
                ),
            ),
        }
    ),
)

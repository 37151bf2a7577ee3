"""Shadow Dexterous Hand (24 joints, 20 actuators), from the gymnasium-robotics MJCF.

The model file is read from the installed ``gymnasium_robotics`` package by path (the package is
not imported, which would register its own environments). Joint names follow the OpenAI/Isaac
convention used by roto: J0 is the distal joint, coupled to J1 by a tendon.
"""

from __future__ import annotations

import importlib.util
import pathlib
from types import MappingProxyType

import mujoco

from roto.robots.spec import BaodingGeometry, BounceScript, Gains, PairRecord, RobotSpec, diagonal_stack

_BAODING_RADIUS = 0.5 * 1.5 * 0.0254

_FINGERS = ("ff", "mf", "rf", "lf", "th")


def gym_assets_dir() -> pathlib.Path:
    """Folder of gymnasium-robotics' MuJoCo assets."""
    found = importlib.util.find_spec("gymnasium_robotics")
    if found is None or not found.submodule_search_locations:
        raise ModuleNotFoundError(
            "the Shadow Hand model comes from the 'gymnasium-robotics' package: pip install gymnasium-robotics"
        )
    return pathlib.Path(found.submodule_search_locations[0]) / "envs" / "assets"


def load_shadow_spec() -> mujoco.MjSpec:
    """The gym Shadow hand as an MjSpec (24 joints, 20 position actuators, 44 fixed tendons)."""
    root = gym_assets_dir()
    hand = root / "hand"
    xml = f"""<mujoco model="shadow">
  <compiler angle="radian" meshdir="{root / "stls" / "hand"}" texturedir="{root / "textures"}"/>
  <include file="{hand / "shared.xml"}"/>
  <asset><include file="{hand / "shared_asset.xml"}"/></asset>
  <worldbody><include file="{hand / "robot.xml"}"/></worldbody>
</mujoco>"""
    return mujoco.MjSpec.from_string(xml)


def _j(name: str) -> str:
    return f"robot0:{name}"


_ACTUATED = tuple(
    _j(n)
    for n in (
        "WRJ1",
        "WRJ0",
        "FFJ3",
        "FFJ2",
        "FFJ1",
        "MFJ3",
        "MFJ2",
        "MFJ1",
        "RFJ3",
        "RFJ2",
        "RFJ1",
        "LFJ4",
        "LFJ3",
        "LFJ2",
        "LFJ1",
        "THJ4",
        "THJ3",
        "THJ2",
        "THJ1",
        "THJ0",
    )
)

SHADOW_BOUNCE = BounceScript(
    swing={"robot0:WRJ0": (0.029, -0.663, 0.337)},
    lean={"robot0:WRJ0": (2.86, 5.66)},
    pose={
        "robot0:FFJ2": 0.439,
        "robot0:MFJ2": 0.439,
        "robot0:RFJ2": 0.439,
        "robot0:LFJ2": 0.439,
        "robot0:FFJ3": -0.192,
        "robot0:MFJ3": -0.085,
        "robot0:RFJ3": -0.26,
        "robot0:LFJ3": -0.226,
        "robot0:THJ4": 1.102,
        "robot0:THJ3": 0.268,
    },
    centre_x=0.0078,
    wind_up_steps=4,
    strike_steps=6,
    settle_speed=0.25,
)


SHADOW = RobotSpec(
    name="shadow",
    display_name="Shadow",
    load_spec=load_shadow_spec,
    root_body="robot0:hand mount",
    actuated_joints=_ACTUATED,
    observed_joints=_ACTUATED,  # docs/spec.md §3: Shadow's pos/vel cover its 20 actuated joints
    tactile_links=tuple(_j(f"{f}distal") for f in _FINGERS)
    + tuple(_j(f"{f}middle") for f in _FINGERS)
    + tuple(_j(f"{f}proximal") for f in _FINGERS)
    + (_j("palm"), _j("lfmetacarpal")),
    gains={"WRJ": Gains(kp=5.0, kv=0.5), "J": Gains(kp=1.0, kv=0.1)},
    # Cupped: wrist bent 0.25 rad so the palm slopes towards the curled fingers, little-finger
    # metacarpal raised, thumb lifted into a side wall (docs/robots.md: how it was found).
    default_pose={
        _j("WRJ0"): -0.25,
        _j("FFJ2"): 0.7,
        _j("MFJ2"): 0.7,
        _j("RFJ2"): 0.7,
        _j("LFJ2"): 0.7,
        _j("LFJ4"): 0.785,
        _j("THJ4"): 0.6,
        _j("THJ3"): 0.5,
    },
    # Tendon T_xxJ1c ties 0.00705·J0 to 0.00805·J1 (gym model, ±1 mm slack).
    coupled_joints={_j(f"{f}J0"): (_j(f"{f}J1"), 0.00805 / 0.00705) for f in ("FF", "MF", "RF", "LF")},
    palm_geom=_j("C_palm0"),
    knuckle_bodies=tuple(_j(f"{f}knuckle") for f in ("ff", "mf", "rf", "lf")),
    tip_bodies=tuple(_j(f"{f}distal") for f in ("ff", "mf", "rf", "lf")),
    thumb_tip=_j("thdistal"),
    tasks=MappingProxyType(
        {
            "bounce": PairRecord(
                reference=27.9, warp_peaks=(10, 62), recipe="bounce_cpu_quickstart", script=SHADOW_BOUNCE
            ),
            "baoding": PairRecord(
                reference=7.31,
                warp_peaks=(12, 65),
                recipe="baoding_cpu",
                geometry=BaodingGeometry(
                    ball_radius=_BAODING_RADIUS,
                    # T_palm: where the dropped ball a comes to rest (rest_after_drop); roto's stack
                    # δ·(1, 1, 1) above it
                    targets=diagonal_stack((0.0577, -0.0079, -0.0066), _BAODING_RADIUS, (1.0, 1.0, 1.0)),
                ),
            ),
        }
    ),
)

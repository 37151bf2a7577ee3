"""ORCA Hand (17 joints, all actuated), from the ``orca-sim`` package, with primitive collision boxes.

``orca-sim`` ships the right hand as ``scene_right.xml`` (options, classes and meshes included); it
is read by path from the installed package and edited with MjSpec: the floor is dropped and each
convex collision mesh is replaced by the box that bounds it (its axis-aligned box in the mesh
frame), which MuJoCo collides faster. Visual meshes stay for rendering.
"""

from __future__ import annotations

import importlib.util
import pathlib
from types import MappingProxyType

import mujoco
import numpy as np

from roto.robots.spec import BaodingGeometry, BounceScript, Gains, PairRecord, RobotSpec, diagonal_stack

_BAODING_RADIUS = 0.5 * 1.5 * 0.0254

_FINGERS = ("index", "middle", "ring", "pinky")


def orca_sim_dir() -> pathlib.Path:
    """Folder of the installed ``orca_sim`` package."""
    found = importlib.util.find_spec("orca_sim")
    if found is None or not found.submodule_search_locations:
        raise ModuleNotFoundError("the ORCA Hand model comes from the 'orca-sim' package: pip install orca-sim")
    return pathlib.Path(found.submodule_search_locations[0])


def _boxes_for_collision_meshes(spec: mujoco.MjSpec) -> None:
    """Replace every colliding mesh geom by its bounding box, named ``<body>_box<k>``."""
    model = spec.compile()
    count: dict[str, int] = {}
    for i, geom in enumerate(spec.geoms):
        if geom.type != mujoco.mjtGeom.mjGEOM_MESH or (geom.contype == 0 and geom.conaffinity == 0):
            continue
        body = model.body(model.geom_bodyid[i]).name
        k = count.get(body, 0)
        count[body] = k + 1
        centre, half = model.geom_aabb[i, :3], model.geom_aabb[i, 3:]
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.geom_quat[i])
        geom.name = f"{body}_box{k}"
        geom.type = mujoco.mjtGeom.mjGEOM_BOX
        geom.meshname = ""
        geom.size = half.copy()
        geom.pos = model.geom_pos[i] + rot.reshape(3, 3) @ centre
        geom.quat = model.geom_quat[i].copy()
        geom.group = 3  # hidden in renders by default; the visual meshes show the hand


def load_orca_spec() -> mujoco.MjSpec:
    """The right ORCA hand as an MjSpec: 17 joints, 17 position actuators, box collisions."""
    spec = mujoco.MjSpec.from_file(str(orca_sim_dir() / "scene_right.xml"))
    for geom in list(spec.geoms):
        if geom.type == mujoco.mjtGeom.mjGEOM_PLANE:
            spec.delete(geom)
    _boxes_for_collision_meshes(spec)
    return spec


def _j(name: str) -> str:
    return f"right_{name}"


_ACTUATED = tuple(
    _j(n)
    for n in (
        "wrist",
        "thumb_mcp",
        "thumb_abd",
        "thumb_pip",
        "thumb_dip",
        "index_abd",
        "index_mcp",
        "index_pip",
        "middle_abd",
        "middle_mcp",
        "middle_pip",
        "ring_abd",
        "ring_mcp",
        "ring_pip",
        "pinky_abd",
        "pinky_mcp",
        "pinky_pip",
    )
)

# ORCA's wrist is strong (kp 100): it winds the fingers down (positive wrist) and strikes back up.
ORCA_BOUNCE = BounceScript(
    swing={"right_wrist": (-0.338, 0.661, 0.227)},
    lean={"right_wrist": (3.112, -2.796)},
    pose={
        **{f"right_{f}_mcp": 0.368 for f in ("index", "middle", "ring", "pinky")},
        **{f"right_{f}_pip": 0.542 for f in ("index", "middle", "ring", "pinky")},
        "right_thumb_abd": -0.397,
        "right_thumb_mcp": -0.87,
    },
    centre_x=-0.012,
    wind_up_steps=6,
    strike_steps=4,
    settle_speed=0.075,
)


ORCA = RobotSpec(
    name="orca",
    display_name="ORCA",
    load_spec=load_orca_spec,
    root_body="right_tower",
    actuated_joints=_ACTUATED,
    observed_joints=_ACTUATED,
    tactile_links=(
        _j("palm"),
        *(_j(f"{f}_{link}") for f in _FINGERS for link in ("mp", "pp", "ip")),
        *(_j(f"thumb_{link}") for link in ("mp", "pp", "ip", "dp")),
    ),
    # docs/spec.md §2 (roto's ORCA drive): wrist kp 100 kd 10; abduction / MCP kp 2 kd 0.1; PIP / DIP kp 4 kd 0.2.
    gains={
        "wrist": Gains(kp=100.0, kv=10.0),
        "pip": Gains(kp=4.0, kv=0.2),
        "dip": Gains(kp=4.0, kv=0.2),
        "abd": Gains(kp=2.0, kv=0.1),
        "mcp": Gains(kp=2.0, kv=0.1),
    },
    # Cupped: fingers bent at the middle joints into a front wall, thumb folded across as a side wall
    # (random search, docs/robots.md); abductions keep the model's rest values.
    default_pose={
        _j("wrist"): 0.051,
        _j("thumb_mcp"): -0.722,
        _j("thumb_abd"): -0.947,
        _j("thumb_pip"): 0.416,
        _j("thumb_dip"): 0.306,
        **{_j(f"{f}_mcp"): 0.198 for f in _FINGERS},
        **{_j(f"{f}_pip"): 0.842 for f in _FINGERS},
    },
    palm_geom="right_palm_box0",
    knuckle_bodies=tuple(_j(f"{f}_mp") for f in _FINGERS),
    tip_bodies=tuple(_j(f"{f}_ip") for f in _FINGERS),
    thumb_tip=_j("thumb_dp"),
    # The bounding boxes are fuller than the meshes: the palm box reaches the fingers' first links.
    excluded_contacts=(
        *((_j("palm"), _j(f"{f}_{link}")) for f in (*_FINGERS, "thumb") for link in ("pp", "ip")),
        (_j("palm"), _j("thumb_mp")),
    ),
    tasks=MappingProxyType(
        {
            "bounce": PairRecord(reference=12.0, warp_peaks=(63, 270), recipe="bounce_cpu_orca", script=ORCA_BOUNCE),
            "baoding": PairRecord(
                reference=5.78,
                warp_peaks=(65, 277),
                recipe="baoding_cpu",
                geometry=BaodingGeometry(
                    ball_radius=_BAODING_RADIUS,
                    # T_palm: where the dropped ball a comes to rest (rest_after_drop); the stack δ·(1, 1, 1)
                    # above it, not roto's ORCA variant δ·(-1, 1, 1), where holding still swaps about once
                    # an episode (docs/tasks.md)
                    targets=diagonal_stack((0.0777, -0.0021, -0.0229), _BAODING_RADIUS, (1.0, 1.0, 1.0)),
                    # above the finger pocket: dropped above the palm centre, 9 of 12 pairs fell off
                    # (docs/tasks.md)
                    drop_centre=(0.073, 0.017, 0.09),
                ),
            ),
        }
    ),
)

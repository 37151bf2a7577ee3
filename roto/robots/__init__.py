"""Robot registry: name -> RobotSpec."""

from __future__ import annotations

from roto.robots.allegro import ALLEGRO
from roto.robots.orca import ORCA
from roto.robots.shadow import SHADOW
from roto.robots.shadow_lite import SHADOW_LITE
from roto.robots.spec import Gains, RobotSpec

ROBOTS: dict[str, RobotSpec] = {robot.name: robot for robot in (SHADOW, SHADOW_LITE, ALLEGRO, ORCA)}

__all__ = ["ROBOTS", "Gains", "RobotSpec", "get_robot"]


def get_robot(name: str) -> RobotSpec:
    """The robot called ``name`` (case-insensitive, '-' or '_'); a clear error lists the valid names."""
    key = str(name).lower().replace("-", "_")
    if key not in ROBOTS:
        raise ValueError(f"unknown robot {name!r}; valid robots: {sorted(ROBOTS)}")
    return ROBOTS[key]

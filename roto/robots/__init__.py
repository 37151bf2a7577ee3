"""Robot registry: name -> RobotSpec."""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from roto.robots.allegro import ALLEGRO
from roto.robots.orca import ORCA
from roto.robots.shadow import SHADOW
from roto.robots.shadow_lite import SHADOW_LITE
from roto.robots.spec import Gains, RobotSpec

ROBOTS: dict[str, RobotSpec] = {robot.name: robot for robot in (SHADOW, SHADOW_LITE, ALLEGRO, ORCA)}
"""Every hand, in the order tables list them."""

__all__ = ["ROBOTS", "Gains", "RobotSpec", "get_robot", "pair_references"]


def pair_references(task: str) -> Mapping[str, float]:
    """{robot: the reference figure of ``task`` on it} from each hand's record of the pair."""
    return MappingProxyType(
        {name: robot.tasks[task].reference for name, robot in ROBOTS.items() if task in robot.tasks}
    )


def get_robot(name: str) -> RobotSpec:
    """The robot called ``name`` (case-insensitive, '-' or '_'); a clear error lists the valid names."""
    key = str(name).lower().replace("-", "_")
    if key not in ROBOTS:
        raise ValueError(f"unknown robot {name!r}; valid robots: {sorted(ROBOTS)}")
    return ROBOTS[key]

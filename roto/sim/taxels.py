"""Taxel grids: box-shaped touch zones over the fingertip pads and the palm of a hand.

A taxel is a MuJoCo ``touch`` sensor on a box site: it reads the normal force of the contacts of
its body that lie inside the box (both backends compute it). The grid of a pad body is laid on the
side of the body that faces the object: of the six faces of the body's collision-geom bounding box
(in the body frame), the one whose outward normal, at the hand's default pose, points most nearly
along ``facing`` (the palm's up direction for the palm; from the fingertip towards a point above
the palm centre for a fingertip). The face is cut into ``rows x cols`` boxes, each reaching from
``OUTSIDE`` beyond the face to the middle of the body, so a contact anywhere on that half of the
pad falls in exactly one taxel.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

OUTSIDE = 0.002
"""How far (m) a taxel box reaches beyond the pad's face, for contact points on its surface."""
FINGERTIP_GRID = (3, 2)
"""Taxels along x across a fingertip pad (rows along the pad's longer side)."""
PALM_GRID = (4, 4)
"""Taxels along x across the palm."""


@dataclass(frozen=True)
class Taxel:
    """One box site in its body's frame: centre (3,), half sizes (3,), body name."""

    body: str
    pos: np.ndarray
    half_size: np.ndarray


def body_box(model: mujoco.MjModel, body_id: int) -> tuple[np.ndarray, np.ndarray]:
    """(lower (3,), upper (3,)) corners of the bounding box of the body's collision geoms, body frame."""
    corners = []
    for geom in np.flatnonzero(model.geom_bodyid == body_id):
        if model.geom_contype[geom] == 0 and model.geom_conaffinity[geom] == 0:
            continue
        centre, half = model.geom_aabb[geom, :3], model.geom_aabb[geom, 3:]
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        local = centre + signs * half  # (8, 3) geom frame
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.geom_quat[geom])
        corners.append(local @ rot.reshape(3, 3).T + model.geom_pos[geom])
    if not corners:
        raise ValueError(f"body {model.body(body_id).name!r} has no collision geoms to lay taxels on")
    points = np.concatenate(corners)
    return points.min(axis=0), points.max(axis=0)


def pad_grid(
    model: mujoco.MjModel, data: mujoco.MjData, body: str, facing: np.ndarray, grid: tuple[int, int]
) -> list[Taxel]:
    """The taxels of ``body``'s face that points most nearly along ``facing`` (world frame, at the
    pose in ``data``), ``grid[0] x grid[1]`` boxes, the first count along the face's longer side."""
    body_id = model.body(body).id
    lower, upper = body_box(model, body_id)
    axes_world = data.xmat[body_id].reshape(3, 3)  # columns: body axes in the world
    alignment = axes_world.T @ (facing / np.linalg.norm(facing))
    normal_axis = int(np.argmax(np.abs(alignment)))
    sign = 1.0 if alignment[normal_axis] > 0 else -1.0
    face = upper[normal_axis] if sign > 0 else lower[normal_axis]
    middle = 0.5 * (lower[normal_axis] + upper[normal_axis])
    others = [a for a in range(3) if a != normal_axis]
    others.sort(key=lambda a: upper[a] - lower[a], reverse=True)  # longer side first
    depth_lo, depth_hi = sorted((middle, face + sign * OUTSIDE))
    taxels = []
    for i in range(grid[0]):
        for j in range(grid[1]):
            lo, hi = lower.copy(), upper.copy()
            lo[normal_axis], hi[normal_axis] = depth_lo, depth_hi
            for axis, k, n in ((others[0], i, grid[0]), (others[1], j, grid[1])):
                step = (upper[axis] - lower[axis]) / n
                lo[axis], hi[axis] = lower[axis] + k * step, lower[axis] + (k + 1) * step
            taxels.append(Taxel(body=body, pos=0.5 * (lo + hi), half_size=0.5 * (hi - lo)))
    return taxels

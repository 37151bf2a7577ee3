"""Episode starts drawn ahead, many at a time, and handed out in order as worlds reset.

An episode start is everything a reset world needs: its initial qpos, joint targets and first
observation frame. The first frame needs the contact sensors at the start state, which takes a
physics evaluation; drawing starts one reset at a time (a handful of worlds per control step under
random actions) paid that evaluation, and some sixty small torch ops, on every step. The pool draws
``size`` starts in one batch (one batched sensor evaluation, spread over all threads or GPU worlds)
and each reset then only copies rows.

Handing starts out reads nothing back from the device: ``take_where`` gathers one row per world by
the rank of each resetting world among this step's resets and advances a cursor that lives on the
device. Only ``ensure`` (drawing more when fewer than needed are left) reads the cursor, so the env
calls it where a host read is free (the CPU) or only every few steps, asking for enough starts to
cover every world resetting on every step until the next call.

The starts are drawn from the env's generator in pool order, so a seed still fixes every episode
start; the draws are the same distribution as drawing per reset, only their order in the random
stream differs.
"""

from __future__ import annotations

from collections.abc import Callable

import torch

Starts = dict[str, torch.Tensor]
"""Name -> tensor with one row per episode start (leading dimension n)."""

MAX_START_PENETRATION = 0.0
"""Deepest self-contact (m) of the hand allowed at an episode start: none at all, so no touch bit
is on at a start (the ball starts in the air)."""

MAX_BALL_START_PENETRATION = 0.001
"""Deepest contact (m) of a ball, with the hand or another ball, allowed at an episode start: the
1 mm the hand's own contacts meet in a resting grasp (a ball dropped from above starts clear)."""

MAX_DRAW_ROUNDS = 100
"""Rounds of drawing replacements for rejected starts before giving up."""


def draw_valid_starts(draw: Callable[[int], Starts], n: int, robot: str) -> Starts:
    """n starts whose hand has no self-contact deeper than ``MAX_START_PENETRATION`` and whose balls
    are nowhere deeper than ``MAX_BALL_START_PENETRATION`` inside the hand or each other.

    ``draw(k)`` returns k candidates with a "penetration" row each (m, the hand's deepest
    self-contact) and a "ball_penetration" row (m, the balls' deepest contact); rejected ones are
    replaced by fresh candidates, round after round, in draw order. Joint noise can press
    neighbouring fingers into each other, or a finger into a ball; such a start would begin with
    the parts kicked apart and touch bits on with nothing touched. Returns the starts without the
    two depths.
    """
    kept: list[Starts] = []
    missing = n
    for _ in range(MAX_DRAW_ROUNDS):
        candidates = draw(missing)
        valid = candidates.pop("penetration") <= MAX_START_PENETRATION
        valid &= candidates.pop("ball_penetration") <= MAX_BALL_START_PENETRATION
        kept.append({name: rows[valid] for name, rows in candidates.items()})
        missing -= int(valid.sum())
        if missing == 0:
            return {name: torch.cat([part[name] for part in kept]) for name in kept[0]}
    raise RuntimeError(
        f"robot {robot!r}: {missing} of {n} episode starts still had the hand pressed into itself or into a "
        f"ball after {MAX_DRAW_ROUNDS} rounds of redrawing; lower reset_joint_noise or move the task's balls"
    )


def contact_depth(found_dist: torch.Tensor) -> torch.Tensor:
    """Penetration depth (m) from a contact sensor's (found, dist) pairs, (..., 2) -> (...): the
    deepest contact's overlap, 0 where the sensor found no contact or the contact has a gap."""
    found, dist = found_dist.unbind(-1)
    return torch.where(found > 0, (-dist).clamp(min=0.0), 0.0)


def check_balls_start_clear(
    draw: Callable[[int, torch.Generator], Starts], robot: str, task: str, device: torch.device, probes: int = 16
) -> None:
    """Refuse a task whose balls start inside the hand or each other in every one of ``probes``
    candidate starts, ``draw(n, generator)``, drawn from a generator of their own (seed 0) so that
    the env's random stream is untouched.

    Raises:
        ValueError naming the robot, the task and the depths.
    """
    generator = torch.Generator(device=device)
    generator.manual_seed(0)
    depth = draw(probes, generator)["ball_penetration"]
    if bool((depth > MAX_BALL_START_PENETRATION).all()):
        raise ValueError(
            f"robot {robot!r}, task {task!r}: the balls start {1000 * float(depth.min()):.1f}-"
            f"{1000 * float(depth.max()):.1f} mm deep inside the hand or each other in all {probes} probe starts "
            f"(at most {1000 * MAX_BALL_START_PENETRATION:.0f} mm allowed); move the balls' start"
        )


class StartPool:
    """A FIFO of episode starts, refilled ``size`` at a time by ``draw(size)``, on ``device``."""

    def __init__(self, draw: Callable[[int], Starts], size: int, device: torch.device | str = "cpu") -> None:
        if size < 1:
            raise ValueError(f"start pool size must be >= 1, got {size}")
        self.size = size
        self._draw = draw
        self._rows: Starts = {}
        self._next = torch.zeros((), dtype=torch.int64, device=device)  # first row not yet handed out

    @property
    def remaining(self) -> int:
        """Starts drawn and not yet handed out (reading it waits for the device)."""
        if not self._rows:
            return 0
        left = len(next(iter(self._rows.values()))) - int(self._next)
        if left < 0:  # only a caller that skipped ``ensure`` can get here
            raise RuntimeError(f"the start pool handed out {-left} starts it did not have; call ensure() first")
        return left

    def ensure(self, n: int) -> None:
        """Make at least ``n`` starts available, drawing ``size`` more at a time (a host read)."""
        while self.remaining < n:
            fresh = self._draw(self.size)
            if self.remaining:
                first = int(self._next)
                fresh = {name: torch.cat([rows[first:], fresh[name]]) for name, rows in self._rows.items()}
            self._rows = fresh
            self._next.zero_()

    def take(self, n: int) -> Starts:
        """The next ``n`` starts, (n, ...) per name (draws more first where fewer are left)."""
        self.ensure(n)
        first = int(self._next)
        self._next += n
        return {name: rows[first : first + n] for name, rows in self._rows.items()}

    def take_where(self, mask: torch.Tensor) -> Starts:
        """One row per world, (B, ...) per name: world i with ``mask[i]`` gets the next start in
        world order; the rows of the other worlds are arbitrary. Reads nothing back; the caller
        has ensured ``mask.sum()`` starts beforehand."""
        rank = torch.cumsum(mask, 0) - 1  # (B,) position of each masked world among them
        last = len(next(iter(self._rows.values()))) - 1
        rows = (self._next + rank).clamp_(0, last)
        self._next += mask.sum()
        return {name: value.index_select(0, rows) for name, value in self._rows.items()}

    def clear(self) -> None:
        """Drop every start drawn so far."""
        self._rows = {}
        self._next.zero_()

    def state_dict(self) -> dict[str, Starts]:
        """Copies of the starts not yet handed out."""
        first = int(self._next)
        return {"rows": {name: rows[first:].clone() for name, rows in self._rows.items()}}

    def load_state_dict(self, state: dict[str, Starts], device: torch.device) -> None:
        """Restore what ``state_dict`` returned."""
        self._rows = {name: rows.clone().to(device) for name, rows in state["rows"].items()}
        self._next = torch.zeros((), dtype=torch.int64, device=device)

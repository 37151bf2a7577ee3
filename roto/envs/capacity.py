"""Per-world contact and constraint capacities of the Warp backend, per (robot, task).

MuJoCo Warp allocates its contact and constraint-row buffers once, when the data is made; a
world that needs more sets an overflow bit and loses contacts. roto sizes them from the peaks
measured by ``benchmarks/contact_peaks.py`` (32 worlds × 600 control steps on the CPU backend, of
both a random-action and a held-pose workload; the larger of the two is kept in each hand's record
of the pair, ``PairRecord.warp_peaks``), doubled and rounded up: contacts to a multiple of 16,
rows to a multiple of 32.
"""

from __future__ import annotations

import math

from roto.robots import get_robot

_MARGIN = 2.0


def _round_up(value: float, multiple: int) -> int:
    return int(math.ceil(value / multiple) * multiple)


def warp_capacity(robot: str, task: str) -> tuple[int, int]:
    """(nconmax, njmax) per world for ``robot`` on ``task``, from the pair's measured peaks
    (``PairRecord.warp_peaks`` in the hand's record) with margin."""
    record = get_robot(robot).tasks.get(task)
    if record is None:
        raise ValueError(f"robot {robot!r} has no record of task {task!r} (no measured contact peaks)")
    ncon, nefc = record.warp_peaks
    return _round_up(_MARGIN * ncon, 16), _round_up(_MARGIN * nefc, 32)

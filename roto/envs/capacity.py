"""Per-world contact and constraint capacities of the Warp backend, per (robot, task).

MuJoCo Warp allocates its contact and constraint-row buffers once, when the data is made; a
world that needs more sets an overflow bit and loses contacts. roto sizes them from the peaks
measured by ``benchmarks/contact_peaks.py`` (32 worlds × 600 control steps on the CPU backend, of
both a random-action and a held-pose workload; the larger of the two is kept here), doubled and
rounded up: contacts to a multiple of 16, rows to a multiple of 32.
"""

from __future__ import annotations

import math

MEASURED_PEAKS: dict[tuple[str, str], tuple[int, int]] = {
    # (robot, task): (max contacts, max constraint rows) in any world at any step
    ("shadow", "bounce"): (10, 62),
    ("shadow", "baoding"): (12, 65),
    ("shadow_lite", "bounce"): (8, 53),
    ("shadow_lite", "baoding"): (9, 48),
    ("allegro", "bounce"): (23, 92),
    ("allegro", "baoding"): (24, 96),
    ("orca", "bounce"): (63, 270),
    ("orca", "baoding"): (65, 277),
}

_MARGIN = 2.0


def _round_up(value: float, multiple: int) -> int:
    return int(math.ceil(value / multiple) * multiple)


def warp_capacity(robot: str, task: str) -> tuple[int, int]:
    """(nconmax, njmax) per world for ``robot`` on ``task``, from the measured peaks with margin."""
    if (robot, task) not in MEASURED_PEAKS:
        valid = sorted(MEASURED_PEAKS)
        raise ValueError(f"no measured contact peaks for robot {robot!r} on task {task!r}; measured pairs: {valid}")
    ncon, nefc = MEASURED_PEAKS[(robot, task)]
    return _round_up(_MARGIN * ncon, 16), _round_up(_MARGIN * nefc, 32)

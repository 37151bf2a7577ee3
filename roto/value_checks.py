"""Checks of one configured value (a count, a real number in a range), raising a ValueError that
names where the value was set, what is valid and what was given: the configs, plans, aids and
command-line flags share them."""

from __future__ import annotations

import math


def check_count(path: str, value: object, low: int, high: int | None = None) -> None:
    """ValueError naming ``path`` unless ``value`` is an int (not a bool) >= ``low`` (and <= ``high``)."""
    if isinstance(value, bool) or not isinstance(value, int) or value < low or (high is not None and value > high):
        valid = f">= {low}" if high is None else f"in [{low}, {high}]"
        raise ValueError(f"{path} must be an integer {valid}, got {value!r}")


def check_number(path: str, value: object, low: float, high: float, what: str) -> None:
    """ValueError naming ``path`` unless ``value`` is a finite real number in [low, high] (``high``
    may be infinite: no upper bound); ``what`` says what the number is ("a share", "a force (N)")."""
    ok = not isinstance(value, bool) and isinstance(value, int | float) and math.isfinite(value)
    if not ok or not low <= value <= high:
        upper = "inf)" if math.isinf(high) else f"{high:g}]"
        raise ValueError(f"{path} must be {what} in [{low:g}, {upper}, got {value!r}")

import math

import pytest

from roto.value_checks import check_count, check_number


def test_a_count_is_an_int_at_or_above_its_low_and_below_its_high():
    check_count("num_envs", 1, 1)
    check_count("seed", 0, 0, 10)
    for value in (0, True, 1.0, "2"):
        with pytest.raises(ValueError, match=rf"^num_envs must be an integer >= 1, got {value!r}$"):
            check_count("num_envs", value, 1)
    with pytest.raises(ValueError, match=r"^seed must be an integer in \[0, 10\], got 11$"):
        check_count("seed", 11, 0, 10)


def test_a_number_is_finite_and_in_its_range_an_infinite_high_reads_as_open():
    check_number("share", 0.5, 0.0, 1.0, "a share")
    check_number("threshold", 1e6, 0.0, math.inf, "a force (N)")
    with pytest.raises(ValueError, match=r"^share must be a share in \[0, 1\], got 1.5$"):
        check_number("share", 1.5, 0.0, 1.0, "a share")
    for value in (-1.0, math.nan, math.inf, "1", False):
        with pytest.raises(ValueError, match=r"^threshold must be a force \(N\) in \[0, inf\), got "):
            check_number("threshold", value, 0.0, math.inf, "a force (N)")

"""A batch that cannot fit in memory is refused before anything is allocated."""

import pytest

import roto
from roto.robots import get_robot
from roto.sim.memory import available_memory, check_fits, cpu_batch_bytes
from roto.sim.scene import build_scene
from roto.tasks.bounce import BALL


def test_a_billion_envs_is_a_clear_error_not_an_allocation():
    if available_memory() is None:
        pytest.skip("this system does not report its available memory")
    with pytest.raises(ValueError, match=r"num_envs 1000000000 needs at least [0-9.]+ GiB .* GiB available"):
        roto.make("bounce", num_envs=1_000_000_000)


def test_the_estimate_scales_with_the_worlds_and_the_limit_names_what_fits():
    model, _ = build_scene(get_robot("shadow"), (BALL,))
    one = cpu_batch_bytes(model, 1, 4)
    assert cpu_batch_bytes(model, 1000, 4) == 1000 * one and one > 8 * model.nq
    check_fits(model, 1000, 4, available=1000 * one)  # exactly fits
    with pytest.raises(ValueError, match=r"which holds those of at most 999 envs"):
        check_fits(model, 1000, 4, available=1000 * one - 1)

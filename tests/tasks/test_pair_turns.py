import math

import pytest
import torch

from roto.tasks.pair_turns import pair_turns


def balls_around(centre: torch.Tensor, angle: torch.Tensor, u: torch.Tensor, v: torch.Tensor, r: float) -> torch.Tensor:
    """(T, 2, 3): two balls opposite each other about ``centre`` at ``angle`` in the plane of u and v."""
    offset = r * (torch.cos(angle)[:, None] * u + torch.sin(angle)[:, None] * v)  # (T, 3)
    return torch.stack([centre - offset, centre + offset], dim=1)


TILTED_U = torch.tensor([1.0, 0.0, 1.0], dtype=torch.float64) / math.sqrt(2)
TILTED_V = torch.tensor([0.0, 1.0, 0.0], dtype=torch.float64)
CENTRE = torch.tensor([0.1, -0.2, 0.3], dtype=torch.float64)


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_a_pair_carried_round_one_way_turns_as_often_as_it_rotates(direction):
    angle = direction * torch.linspace(0, 3 * 2 * math.pi, 601, dtype=torch.float64)  # 3 turns in 600 steps
    net, travelled = pair_turns(balls_around(CENTRE, angle, TILTED_U, TILTED_V, 0.02))
    assert net == pytest.approx(3.0, abs=1e-9) and travelled == pytest.approx(3.0, abs=1e-9)


def test_a_pair_swung_back_and_forth_travels_but_does_not_turn():
    t = torch.linspace(0, 12 * math.pi, 601, dtype=torch.float64)  # six swings out and back
    angle = 0.4 * math.pi * (1 - torch.cos(t)) + 0.001 * torch.sin(7 * t)  # 0 to 0.8 pi and back, a little wobble
    net, travelled = pair_turns(balls_around(CENTRE, angle, TILTED_U, TILTED_V, 0.02))
    assert net < 0.01 and travelled == pytest.approx(6 * 2 * 0.4, rel=0.01)


def test_the_measure_does_not_depend_on_where_or_how_tilted_the_plane_is():
    angle = torch.linspace(0, 2 * math.pi, 301, dtype=torch.float64)
    up = torch.tensor([0.0, 0.0, 1.0], dtype=torch.float64)
    flat = pair_turns(balls_around(torch.zeros(3, dtype=torch.float64), angle, TILTED_V, up, 0.03))
    tilted = pair_turns(balls_around(CENTRE, angle, TILTED_U, TILTED_V, 0.03))
    assert flat == pytest.approx(tilted, abs=1e-9) and flat[0] == pytest.approx(1.0, abs=1e-9)


def test_a_held_pair_turns_not_at_all_and_bad_shapes_are_refused():
    still = balls_around(CENTRE, torch.zeros(50, dtype=torch.float64), TILTED_U, TILTED_V, 0.02)
    assert pair_turns(still) == (0.0, 0.0) and pair_turns(still[:1]) == (0.0, 0.0)
    with pytest.raises(ValueError, match=r"shape \(T, 2, 3\), got \(50, 6\)"):
        pair_turns(still.reshape(50, 6))


def test_baodings_path_metrics_are_the_pairs_turns_and_the_rotations_its_net_turning_backs():
    from roto.tasks.baoding import Baoding

    task = Baoding()
    one_turn = torch.linspace(0, 2 * math.pi, 201, dtype=torch.float64)
    once_round = balls_around(CENTRE, one_turn, TILTED_U, TILTED_V, 0.02)
    net, travelled = pair_turns(once_round)
    assert net == pytest.approx(1.0)
    metrics = task.path_metrics(once_round, {"swaps": 2.0, "rotations": 1.0})
    assert metrics == {"net_turns": net, "travelled_turns": travelled, "round_rotations": min(1.0, net)}
    counted_not_turned = task.path_metrics(once_round, {"swaps": 6.0, "rotations": 3.0})
    turned_not_swapped = task.path_metrics(once_round, {"swaps": 0.0, "rotations": 0.0})
    assert counted_not_turned["round_rotations"] == net and turned_not_swapped["round_rotations"] == 0.0
    out_and_back = torch.cat([torch.linspace(0, math.pi, 101), torch.linspace(math.pi, 0, 101)[1:]]).to(torch.float64)
    swing = balls_around(CENTRE, out_and_back.repeat(3), TILTED_U, TILTED_V, 0.02)  # three swings: six swaps
    metrics = task.path_metrics(swing, {"swaps": 6.0, "rotations": 3.0})
    assert metrics["round_rotations"] == metrics["net_turns"] < 0.01
    assert metrics["travelled_turns"] == pytest.approx(3.0)


def test_baodings_derived_metrics_need_both_rotations_and_net_turns():
    from roto.tasks import get_task

    task = get_task("baoding")
    assert task.derived_metrics({"rotations": 3.0, "net_turns": 0.25}) == {"round_rotations": 0.25}
    assert task.derived_metrics({"rotations": 1.0, "net_turns": 1.4}) == {"round_rotations": 1.0}
    assert task.derived_metrics({"rotations": 3.0}) == {}
    assert get_task("bounce").derived_metrics({"bounces": 60.0}) == {}


def test_baodings_path_kind_tells_a_round_policy_from_a_swing_and_one_that_never_swaps():
    from roto.tasks import get_task

    task = get_task("baoding")
    assert task.path_kind({"rotations": 10.0, "net_turns": 8.0}) == "round"  # exactly 0.8 of its rotations
    assert task.path_kind({"rotations": 10.0, "net_turns": 7.9}) == "swing"
    assert task.path_kind({"rotations": 13.3, "net_turns": 0.26}) == "swing"
    assert task.path_kind({"rotations": 0.9, "net_turns": 0.0}) == "no swaps"
    assert task.path_kind({"rotations": 3.0}) is None and get_task("bounce").path_kind({"bounces": 60.0}) is None

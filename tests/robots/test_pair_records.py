"""Each hand's record of each (task, hand) pair: what was measured there, read by the tasks and
the Warp backend instead of tables of their own."""

import pytest

from roto.robots import ROBOTS, get_robot, pair_references
from roto.robots.spec import PairRecord
from roto.tasks import TASKS, get_task


@pytest.mark.parametrize("robot", ROBOTS)
def test_every_hand_has_a_measured_record_of_every_task(robot):
    spec = get_robot(robot)
    assert set(spec.tasks) == set(TASKS)
    for task, record in spec.tasks.items():
        assert isinstance(record, PairRecord) and record.reference > 0.0
        assert (record.script is not None) == (task == "bounce")  # Bounce's reference is a scripted motion
        assert get_task(task).reference[robot] == record.reference  # the task reads the hand's record
        contacts, rows = record.warp_peaks
        nconmax, njmax = record.warp_capacity
        assert nconmax >= 2 * contacts and njmax >= 2 * rows and nconmax % 16 == 0 and njmax % 32 == 0


def test_references_follow_the_hand_registry_and_a_missing_pair_is_named():
    assert list(pair_references("bounce")) == list(ROBOTS) == ["shadow", "shadow_lite", "allegro", "orca"]
    assert pair_references("bounce")["shadow"] == 27.9 and pair_references("baoding")["allegro"] == 5.03
    assert pair_references("juggle") == {}

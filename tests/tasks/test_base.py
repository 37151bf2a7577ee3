from roto.tasks import get_task
from roto.tasks.base import lead_metric


def test_baoding_leads_with_round_rotations_only_where_every_record_measured_them():
    baoding = get_task("baoding")
    assert lead_metric(baoding) == "round_rotations"  # no records: the task's own lead
    measured = [{"rotations_mean": 3.0, "round_rotations_mean": 0.25}] * 2
    assert lead_metric(baoding, measured) == "round_rotations"
    assert lead_metric(baoding, [*measured, {"rotations_mean": 3.0}]) == "rotations"  # one older record


def test_a_task_without_a_selection_metric_leads_with_its_headline():
    bounce = get_task("bounce")
    assert bounce.selection_metric is None
    assert lead_metric(bounce, [{"bounces_mean": 1.0}]) == "bounces" == lead_metric(bounce)

from roto.eval.plots import best_evaluation


def records(*rows):
    return [{"return_mean": ret, "round_rotations_mean": rnd} for ret, rnd in rows]


def test_best_evaluation_ranks_as_training_does_by_the_selection_metric_first():
    # a swing (high return, 0.25 round rotations) never outranks a policy that goes round
    rows = records((300.0, 0.25), (250.0, 9.0), (260.0, 9.0), (100.0, 2.0))
    assert best_evaluation(rows, "round_rotations") == 2  # equal round rotations: the higher return
    assert best_evaluation(rows) == 0  # a task without a selection metric: the return alone


def test_best_evaluation_keeps_the_first_of_equals_and_reads_records_without_the_metric():
    assert best_evaluation(records((5.0, 1.0), (5.0, 1.0)), "round_rotations") == 0
    older = [{"return_mean": 1.0}, {"return_mean": 3.0}]  # evaluations from before paths were measured
    assert best_evaluation(older, "round_rotations") == 1
    resumed = [*older, *records((2.0, 0.5))]  # a run resumed by code that measures the metric
    assert best_evaluation(resumed, "round_rotations") == 2

import numpy as np
import pytest

from roto.olympiad.stats import iqm, probability_of_improvement, stratified_bootstrap_ci


def test_iqm_drops_the_lowest_and_highest_quarter():
    assert iqm(np.arange(1.0, 9.0)) == 4.5  # 1..8: mean of 3, 4, 5, 6
    assert iqm(np.array([10.0, 1.0, 3.0, 2.0, 100.0])) == 5.0  # floor(5/4) = 1 cut each side: mean of 2, 3, 10
    assert iqm(np.array([[1.0, 7.0], [3.0, 5.0]])) == 4.0  # pooled over runs and tasks
    assert iqm(np.array([2.0, 4.0])) == 3.0  # fewer than 4 values: nothing cut


def test_bootstrap_interval_of_two_runs_spans_their_resamples():
    # resamples of [0, 10] have means 0, 5, 10 with probability 1/4, 1/2, 1/4: the 95 % interval is [0, 10]
    assert stratified_bootstrap_ci(np.array([[0.0], [10.0]]), reps=4000) == (0.0, 10.0)
    assert stratified_bootstrap_ci(np.full((3, 2), 7.0)) == (7.0, 7.0)


def test_bootstrap_resamples_runs_within_each_task():
    # task A's runs are all 0 and task B's all 100: any within-task resample pools two of each, so its
    # IQM (drop one each side of four values) is 50; resampling across tasks would not be constant
    scores = np.array([[0.0, 100.0], [0.0, 100.0]])
    assert stratified_bootstrap_ci(scores, reps=500) == (50.0, 50.0)


def test_bootstrap_is_reproducible_for_a_seed():
    scores = np.random.default_rng(1).normal(size=(5, 3))
    assert stratified_bootstrap_ci(scores, seed=3) == stratified_bootstrap_ci(scores, seed=3)
    low, high = stratified_bootstrap_ci(scores, seed=3)
    assert low < iqm(scores) < high


def test_probability_of_improvement_counts_pairs_and_half_ties():
    x, y = np.array([[1.0], [2.0], [3.0]]), np.array([[2.0]])
    assert probability_of_improvement(x, y) == pytest.approx(0.5)  # (0 + 1/2 + 1) / 3
    assert probability_of_improvement(y, x) == pytest.approx(0.5)
    assert probability_of_improvement(np.array([[5.0, 0.0]]), np.array([[1.0, 1.0]])) == 0.5  # tasks averaged
    assert probability_of_improvement(np.array([[3.0], [4.0]]), np.array([[1.0], [2.0]])) == 1.0


def test_the_difference_interval_of_constant_groups_is_their_difference_and_widens_with_spread():
    from roto.olympiad.stats import difference_ci

    assert difference_ci([5.0, 5.0, 5.0], [2.0, 2.0]) == (3.0, 3.0)
    low, high = difference_ci([4.0, 6.0, 5.0, 7.0], [1.0, 3.0, 2.0])
    assert 1.0 <= low < 5.5 - 2.0 < high <= 6.0  # around the difference of means, within 4 - 3 and 7 - 1


def test_the_paired_interval_resamples_seed_pairs_not_groups():
    import pytest

    from roto.olympiad.stats import paired_difference_ci

    # every seed gains exactly 2 while the seeds themselves spread widely: the pairs leave no doubt
    assert paired_difference_ci([12.0, 1.0, 30.0], [10.0, -1.0, 28.0]) == (2.0, 2.0)
    low, high = paired_difference_ci([3.0, 5.0, 4.0, 9.0], [1.0, 1.0, 1.0, 1.0])
    assert 2.0 <= low < 4.25 < high <= 8.0  # around the mean difference, within the smallest and largest
    with pytest.raises(ValueError, match="one value per seed on both sides, got 3 and 2"):
        paired_difference_ci([1.0, 2.0, 3.0], [1.0, 2.0])

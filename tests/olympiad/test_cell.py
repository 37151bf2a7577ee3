from roto.olympiad.cell import training_curve


def test_training_curve_averages_each_scalar_between_evaluations():
    scalars = {
        "ppo/action_std": ([10, 20, 30, 40], [1.0, 2.0, 3.0, 5.0]),
        "train/episode_swaps": ([20, 40], [0.5, 1.5]),
        "loss/value": ([10, 20, 30, 40], [9.0, 9.0, 9.0, 9.0]),  # not a training-episode scalar: left out
    }
    rows = training_curve(scalars, [20, 30, 40])
    assert rows == [
        {"env_steps": 20, "ppo/action_std": 1.5, "train/episode_swaps": 0.5},
        {"env_steps": 30, "ppo/action_std": 3.0},  # no training episode ended in (20, 30]
        {"env_steps": 40, "ppo/action_std": 5.0, "train/episode_swaps": 1.5},
    ]


def test_training_curve_of_no_evaluations_is_empty():
    assert training_curve({"ppo/action_std": ([10], [1.0])}, []) == []

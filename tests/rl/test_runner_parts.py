import pytest
import torch

from roto.rl.episode_stats import EpisodeStats
from roto.rl.networks import concat_groups
from roto.rl.torch_threads import single_torch_thread


def info(done, returns, lengths, bounces):
    return {
        "_episode": torch.tensor(done),
        "episode": {"r": torch.tensor(returns), "l": torch.tensor(lengths), "bounces": torch.tensor(bounces)},
    }


def test_episode_stats_average_only_the_episodes_that_ended_then_start_over():
    stats = EpisodeStats(("bounces",), torch.device("cpu"))
    stats.add({})
    assert stats.read() == {}
    stats.add(info([True, False], [10.0, 99.0], [600, 1], [1.0, 9.0]))
    stats.add(info([True, True], [20.0, 30.0], [300, 600], [2.0, 3.0]))
    means = stats.read()
    assert means["train/episode_return"] == pytest.approx(20.0)
    assert means["train/episode_length"] == pytest.approx(500.0)
    assert means["train/episode_bounces"] == pytest.approx(2.0)
    assert stats.read() == {}  # read resets


def test_concat_groups_follows_the_listed_order():
    obs = {"tactile": torch.ones(2, 3, dtype=torch.float32), "proprio": torch.zeros(2, 4, dtype=torch.float64)}
    flat = concat_groups(obs, ("proprio", "tactile"))
    assert flat.shape == (2, 7) and flat.dtype == torch.float32
    assert flat[:, :4].eq(0).all() and flat[:, 4:].eq(1).all()


def test_rollouts_run_on_one_torch_thread_and_the_count_comes_back():
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        with single_torch_thread(torch.device("cpu")):
            assert torch.get_num_threads() == 1
        assert torch.get_num_threads() == 2
        with pytest.raises(KeyError), single_torch_thread(torch.device("cpu")):
            raise KeyError("inside the block")
        assert torch.get_num_threads() == 2
        with single_torch_thread(torch.device("meta")):  # not the CPU: left alone
            assert torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)

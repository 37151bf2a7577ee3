import pytest
import torch

from roto.rl.runner import EvalRounds, flatten_obs, single_torch_thread


def info(done, returns, lengths, bounces):
    return {
        "_episode": torch.tensor(done),
        "episode": {"r": torch.tensor(returns), "l": torch.tensor(lengths), "bounces": torch.tensor(bounces)},
    }


def test_eval_round_closes_after_size_episodes_and_keeps_the_rest():
    rounds = EvalRounds(size=3, metric_names=("bounces",))
    assert rounds.add({}) is None
    assert rounds.add(info([True, False], [10.0, 99.0], [600, 1], [1.0, 9.0])) is None
    stats = rounds.add(info([True, True], [20.0, 30.0], [300, 600], [2.0, 3.0]))
    assert stats is not None
    assert stats["eval/return_mean"] == pytest.approx(20.0)
    assert stats["eval/return_std"] == pytest.approx((200.0 / 3) ** 0.5)
    assert stats["eval/bounces_mean"] == pytest.approx(2.0)
    assert stats["eval/length_mean"] == pytest.approx(500.0)
    assert rounds.pending["return"] == []  # exactly three were finished: nothing carried over
    rounds.add(info([True, True], [1.0, 2.0], [5, 6], [0.0, 0.0]))
    stats = rounds.add(info([True, True], [3.0, 4.0], [7, 8], [0.0, 0.0]))
    assert stats["eval/return_mean"] == pytest.approx(2.0)  # episodes 1, 2, 3; episode 4 waits
    assert rounds.pending["return"] == [4.0]


def test_flatten_obs_concatenates_groups_in_order():
    obs = {"tactile": torch.ones(2, 3, dtype=torch.float32), "proprio": torch.zeros(2, 4, dtype=torch.float64)}
    flat = flatten_obs(obs)
    assert flat.shape == (2, 7) and flat.dtype == torch.float32
    assert flat[:, :3].eq(1).all() and flat[:, 3:].eq(0).all()


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

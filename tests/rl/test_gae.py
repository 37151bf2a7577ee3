import pytest
import torch

from roto.rl.gae import compute_gae


def test_gae_matches_hand_computed_values_with_a_termination():
    rewards = torch.tensor([[1.0], [2.0], [3.0]])
    values = torch.tensor([[0.5], [0.5], [0.5]])
    dones = torch.tensor([[False], [True], [False]])
    last = torch.tensor([2.0])
    adv, ret = compute_gae(rewards, values, dones, last, gamma=0.9, lam=0.8)
    # t=2: 3 + 0.9*2 - 0.5 = 4.3; t=1 ends the episode: 2 - 0.5 = 1.5; t=0: 0.95 + 0.72*1.5 = 2.03
    assert adv[:, 0].tolist() == pytest.approx([2.03, 1.5, 4.3])
    assert ret[:, 0].tolist() == pytest.approx([2.53, 2.0, 4.8])


def test_gae_with_lambda_one_is_the_discounted_return_minus_value():
    rewards = torch.tensor([[1.0, 0.0], [1.0, 1.0], [1.0, 2.0]])
    values = torch.zeros(3, 2)
    dones = torch.zeros(3, 2, dtype=torch.bool)
    _, ret = compute_gae(rewards, values, dones, torch.tensor([10.0, 0.0]), gamma=0.5, lam=1.0)
    assert ret[0].tolist() == pytest.approx([1 + 0.5 + 0.25 + 0.125 * 10, 0 + 0.5 + 0.5])


def test_a_time_out_cuts_the_trace_and_bootstrapping_is_added_through_the_reward():
    # roto's default: a truncation is a done like a termination (no bootstrap). With
    # bootstrap_timeouts, the runner adds gamma * V(final_obs) to that step's reward.
    values = torch.tensor([[1.0], [1.0]])
    dones = torch.tensor([[True], [False]])
    plain, _ = compute_gae(torch.tensor([[0.0], [0.0]]), values, dones, torch.tensor([1.0]), 0.9, 0.95)
    boot, _ = compute_gae(torch.tensor([[0.9 * 3.0], [0.0]]), values, dones, torch.tensor([1.0]), 0.9, 0.95)
    assert plain[0, 0].item() == pytest.approx(-1.0)
    assert boot[0, 0].item() == pytest.approx(2.7 - 1.0)

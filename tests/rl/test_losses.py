import math

import pytest
import torch

from roto.rl.losses import kl_adaptive_lr, ppo_terms, weighted_sum


def test_ppo_loss_terms_on_a_hand_checked_batch():
    terms, m = ppo_terms(
        log_prob=torch.tensor([math.log(1.5), math.log(0.5)]),
        old_log_prob=torch.zeros(2),
        advantages=torch.tensor([1.0, -1.0]),
        values=torch.tensor([1.0, 0.0]),
        old_values=torch.tensor([0.5, 0.5]),
        returns=torch.tensor([2.0, 0.0]),
        entropy=torch.tensor([1.0, 3.0]),
        ratio_clip=0.2,
        value_clip=0.2,
    )
    # ratios 1.5, 0.5 -> min(surrogate, clipped) = 1.2, -0.8 -> policy loss -0.2
    assert terms["surrogate"].item() == pytest.approx(-0.2)
    # clipped values 0.7, 0.3 -> ((2 - 0.7)^2 + 0.3^2) / 2
    assert terms["value"].item() == pytest.approx(0.89)
    assert terms["entropy"].item() == pytest.approx(2.0)
    loss = weighted_sum(terms, {"surrogate": 1.0, "value": 0.5, "entropy": -0.01})
    assert loss.item() == pytest.approx(-0.2 + 0.5 * 0.89 - 0.01 * 2.0)
    with pytest.raises(KeyError, match="value"):
        weighted_sum(terms, {"surrogate": 1.0, "entropy": -0.01})
    assert m["approx_kl"].item() == pytest.approx(((0.5 - math.log(1.5)) + (-0.5 + math.log(2.0))) / 2)
    assert m["clip_fraction"].item() == 1.0


def test_unclipped_ratio_gives_the_plain_policy_gradient():
    logp = torch.zeros(3, requires_grad=True)
    adv = torch.tensor([1.0, 2.0, -3.0])
    terms, _ = ppo_terms(logp, torch.zeros(3), adv, torch.zeros(3), torch.zeros(3), torch.zeros(3), torch.zeros(3),
                         ratio_clip=0.2, value_clip=0.2)  # fmt: skip
    terms["surrogate"].backward()
    assert logp.grad.tolist() == pytest.approx((-adv / 3).tolist())


def test_kl_adaptive_lr_moves_by_the_factor_and_stays_in_bounds():
    assert kl_adaptive_lr(1e-3, 0.05, 0.008, 1.5, 1e-6, 1e-2) == pytest.approx(1e-3 / 1.5)
    assert kl_adaptive_lr(1e-3, 0.001, 0.008, 1.5, 1e-6, 1e-2) == pytest.approx(1.5e-3)
    assert kl_adaptive_lr(1e-3, 0.008, 0.008, 1.5, 1e-6, 1e-2) == pytest.approx(1e-3)
    assert kl_adaptive_lr(9e-3, 0.0001, 0.008, 1.5, 1e-6, 1e-2) == pytest.approx(1e-2)

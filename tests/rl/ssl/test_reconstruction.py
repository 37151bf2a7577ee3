import math

import pytest
import torch

from roto.rl.networks import ActorCritic
from roto.rl.ssl.configs import FullReconstructionConfig, ReconstructionConfig
from roto.rl.ssl.reconstruction import Reconstruction, rare_bit_bce

SIZES = {"tactile": 3, "proprio": 2}


def small_model():
    torch.manual_seed(0)
    return ActorCritic(SIZES, 2, actor_groups=("tactile", "proprio"), encoder=(8,), policy_head=(4,), value_head=(4,))


def test_rare_bits_weigh_their_positives_by_their_rarity():
    # bit 0 is on in 1 of 4 samples: p = 1/4, pos weight 3; bit 1 never on: weight capped at 1e4
    bits = torch.tensor([[1.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]])
    logits = torch.zeros(4, 2)
    log2 = math.log(2.0)
    # every element costs log 2 at logit 0; the one positive costs 3 log 2
    expected = (3 * log2 + 3 * log2 + 4 * log2) / 8
    assert rare_bit_bce(logits, bits).item() == pytest.approx(expected)


def test_full_reconstruction_is_bce_on_touch_plus_mse_on_proprioception_with_gradients_to_the_encoder():
    model = small_model()
    loss_fn = Reconstruction("full_reconstruction", FullReconstructionConfig(), model, SIZES)
    obs = {"tactile": torch.tensor([[1.0, 0.0, 1.0], [0.0, 0.0, 1.0]]), "proprio": torch.randn(2, 2)}
    latent = model.encode(obs)
    loss, metrics = loss_fn.loss(model, {"obs": obs}, latent, None)
    logits_proprio, logits_tactile = loss_fn.heads(latent).split([2, 3], dim=-1)
    expected_mse = (logits_proprio - obs["proprio"]).square().mean()
    expected_bce = rare_bit_bce(logits_tactile, obs["tactile"])
    assert loss.item() == pytest.approx((expected_mse + expected_bce).item())
    assert metrics["proprio"].item() == pytest.approx(expected_mse.item())
    loss.backward()
    assert model.encoder[0].weight.grad.abs().sum() > 0
    assert all(p.grad is not None for p in loss_fn.heads.parameters())
    assert model.policy_mean.weight.grad is None  # nothing else of the actor-critic is touched


def test_reconstruction_shapes_and_its_optimizer_holds_the_encoder():
    model = small_model()
    loss_fn = Reconstruction("tactile_reconstruction", ReconstructionConfig(decoder=(16, 32)), model, SIZES)
    assert loss_fn.heads(torch.zeros(5, model.latent_width)).shape == (5, 3)
    held = {id(p) for group in loss_fn.optimizer.param_groups for p in group["params"]}
    assert all(id(p) in held for p in model.encoder.parameters())
    assert not any(id(p) in held for p in model.policy_mean.parameters())


def test_a_target_group_the_env_does_not_provide_is_an_error():
    with pytest.raises(ValueError, match=r"ssl.tactile_reconstruction.targets.*\['privileged'\]"):
        Reconstruction("tactile_reconstruction", ReconstructionConfig(targets=("privileged",)), small_model(), SIZES)


def test_force_touch_is_decoded_with_mse_not_bce():
    model = small_model()
    loss_fn = Reconstruction("tactile_reconstruction", ReconstructionConfig(), model, SIZES, touch="force")
    obs = {"tactile": torch.tensor([[0.0, 1.4, 4.6], [0.0, 0.0, 2.0]]), "proprio": torch.randn(2, 2)}
    latent = model.encode(obs)
    loss, metrics = loss_fn.loss(model, {"obs": obs}, latent, None)
    expected = (loss_fn.heads(latent) - obs["tactile"]).square().mean()
    assert loss.item() == pytest.approx(expected.item())
    assert metrics["tactile"].item() == pytest.approx(expected.item())

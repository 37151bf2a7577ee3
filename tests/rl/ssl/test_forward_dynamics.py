import pytest
import torch

from roto.rl.networks import ActorCritic
from roto.rl.ssl.configs import ForwardDynamicsConfig
from roto.rl.ssl.forward_dynamics import ForwardDynamics, ResidualLatentModel, forward_dynamics_loss

SIZES = {"proprio": 3}


def setup(seq_length=3):
    torch.manual_seed(0)
    model = ActorCritic(SIZES, 2, actor_groups=("proprio",), encoder=(6,), policy_head=(4,), value_head=(4,),
                        obs_normalization=False)  # fmt: skip
    loss_fn = ForwardDynamics("forward_dynamics", ForwardDynamicsConfig(seq_length=seq_length, tau=0.25), model, 2)
    return model, loss_fn


def test_loss_sums_over_time_the_mean_over_batch_and_latent_dims():
    prediction = torch.zeros(2, 3, 4)
    target = torch.zeros(2, 3, 4)
    target[0, 0] = 2.0  # step 0: mean of squares over 2 x 4 = 4 * 4 / 8 = 2
    target[:, 2, :2] = 1.0  # step 2: 4 ones over 8 = 0.5
    assert forward_dynamics_loss(prediction, target).item() == pytest.approx(2.5)


def test_the_latent_model_is_residual():
    g = ResidualLatentModel(4, 2, (8,))
    torch.nn.init.zeros_(g.net[-1].weight)
    torch.nn.init.zeros_(g.net[-1].bias)
    z = torch.randn(5, 4)
    assert torch.equal(g(z, torch.randn(5, 2)), z)


def test_loss_value_and_gradients_reach_the_online_encoder_never_the_target():
    model, loss_fn = setup()
    batch = {"obs": {"proprio": torch.randn(4, 3, 3)}, "actions": torch.randn(4, 3, 2)}
    loss, metrics = loss_fn.loss(model, {}, torch.zeros(1), batch)
    z = model.encoder(batch["obs"]["proprio"])
    with torch.no_grad():
        target = loss_fn.target_encoder(batch["obs"]["proprio"])[:, 1:]
    predicted = loss_fn.heads["projector"](loss_fn.heads["latent_model"](z[:, :-1], batch["actions"][:, :-1]))
    expected = (predicted - target).square().mean(dim=(0, 2)).sum()
    assert loss.item() == pytest.approx(expected.item())
    assert metrics["latent_mse"].item() == pytest.approx(expected.item() / 2)
    loss.backward()
    assert model.encoder[0].weight.grad.abs().sum() > 0
    assert all(p.grad is None for p in loss_fn.target_encoder.parameters())
    assert not any(p.requires_grad for p in loss_fn.target_encoder.parameters())


def test_the_target_encoder_follows_the_online_one_by_ema():
    model, loss_fn = setup()
    before = [p.clone() for p in loss_fn.target_encoder.parameters()]
    with torch.no_grad():
        for p in model.encoder.parameters():
            p.add_(1.0)
    loss_fn.after_step(model)
    for old, new, online in zip(before, loss_fn.target_encoder.parameters(), model.encoder.parameters(), strict=True):
        assert torch.allclose(new, 0.75 * old + 0.25 * online)


def test_a_batch_without_sequences_gives_a_zero_loss_that_still_backpropagates():
    model, loss_fn = setup()
    latent = model.encode({"proprio": torch.randn(2, 3)})
    empty = {"obs": {"proprio": torch.zeros(0, 3, 3)}, "actions": torch.zeros(0, 3, 2)}
    loss, _ = loss_fn.loss(model, {}, latent, empty)
    assert loss.item() == 0.0
    loss.backward()

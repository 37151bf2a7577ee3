import pytest
import torch

from roto.rl.networks import ActorCritic

SIZES = {"tactile": 4, "proprio": 8}


def step_on(model, optimizer, loss):
    optimizer.zero_grad()
    loss.backward()
    optimizer.step()
    model.after_optimizer_step()


def test_a_projected_log_std_can_shrink_from_its_bound_and_a_clamped_one_cannot():
    for project in (False, True):
        model = ActorCritic(SIZES, 3, actor_groups=("tactile", "proprio"), encoder=(8,), max_log_std=0.0,
                            project_log_std=project)  # fmt: skip
        optimizer = torch.optim.SGD([model.log_std], lr=0.5)
        step_on(model, optimizer, -model.clamped_log_std().sum())  # an entropy bonus pushes the std up
        assert torch.equal(model.log_std.detach(), torch.full((3,), 0.0 if project else 0.5))
        step_on(model, optimizer, model.clamped_log_std().sum())  # then the loss wants it smaller
        expected = torch.full((3,), -0.5 if project else 0.5)  # clamped past the bound: no gradient, stuck
        assert torch.equal(model.log_std.detach(), expected), (project, model.log_std)
        assert torch.equal(model.clamped_log_std().detach(), expected.clamp(max=0.0))


def test_a_policy_started_at_an_action_means_it_for_any_input_and_still_learns():
    torch.manual_seed(0)
    model = ActorCritic(SIZES, 3, actor_groups=("tactile", "proprio"), encoder=(8,))
    obs = {"tactile": torch.randn(64, 4), "proprio": torch.randn(64, 8)}
    start = torch.tensor([0.5, -0.25, 0.75])
    assert (model.act_deterministic(obs) - start).abs().max() > 0.1  # the default init acts elsewhere
    model.start_mean_at(start)
    assert (model.act_deterministic(obs) - start).abs().max() < 0.02
    optimizer = torch.optim.SGD(model.policy_mean.parameters(), lr=0.1)
    before = model.act_deterministic(obs)
    step_on(model, optimizer, (model(obs)[0] - 1.0).square().mean())  # the weights still get a gradient
    assert not torch.equal(model.act_deterministic(obs), before)


def test_a_start_action_of_another_size_or_a_gain_outside_0_1_is_refused():
    model = ActorCritic(SIZES, 3, actor_groups=("tactile", "proprio"), encoder=(8,))
    for action, gain, message in [
        (torch.zeros(4), 0.01, r"shape \(3,\), got \(4,\)"),
        (torch.zeros(3), 2.0, "got 2.0"),
    ]:
        with pytest.raises(ValueError, match=message):
            model.start_mean_at(action, gain)

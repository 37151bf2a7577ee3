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

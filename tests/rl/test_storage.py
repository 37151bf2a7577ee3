import pytest
import torch

from roto.rl.storage import RolloutBuffer


def test_shapes_and_every_sample_in_exactly_one_minibatch():
    buf = RolloutBuffer(5, 3, {"proprio": 4, "tactile": 1}, num_actions=2, device=torch.device("cpu"))
    for t in range(5):
        obs = torch.arange(3, dtype=torch.float32)[:, None].expand(3, 4) + 10 * t
        obs = {"proprio": obs, "tactile": obs[:, :1] + 0.5}
        buf.add(
            obs, torch.zeros(3, 2), torch.zeros(3), torch.zeros(3), torch.zeros(3), torch.zeros(3, dtype=torch.bool)
        )
    assert (
        buf.obs["proprio"].shape == (5, 3, 4)
        and buf.obs["tactile"].shape == (5, 3, 1)
        and buf.actions.shape == (5, 3, 2)
        and buf.rewards.shape == (5, 3)
    )
    batches = list(buf.minibatches(4, torch.Generator().manual_seed(0)))
    assert len(batches) == 4
    seen = torch.cat([b["obs"]["proprio"][:, 0] for b in batches])
    assert sorted(seen.tolist()) == sorted(buf.obs["proprio"][..., 0].flatten().tolist())
    for b in batches:  # the groups of a sample stay together
        assert torch.equal(b["obs"]["tactile"][:, 0], b["obs"]["proprio"][:, 0] + 0.5)
    with pytest.raises(RuntimeError, match="full"):
        buf.add(
            obs, torch.zeros(3, 2), torch.zeros(3), torch.zeros(3), torch.zeros(3), torch.zeros(3, dtype=torch.bool)
        )
    with pytest.raises(ValueError, match="num_minibatches"):
        next(buf.minibatches(16, torch.Generator()))

import pytest
import torch

from roto.rl.storage import RolloutBuffer


def test_shapes_and_every_sample_in_exactly_one_minibatch():
    buf = RolloutBuffer(steps=5, num_envs=3, obs_dim=4, num_actions=2, device=torch.device("cpu"))
    for t in range(5):
        obs = torch.arange(3, dtype=torch.float32)[:, None].expand(3, 4) + 10 * t
        buf.add(
            obs, torch.zeros(3, 2), torch.zeros(3), torch.zeros(3), torch.zeros(3), torch.zeros(3, dtype=torch.bool)
        )
    assert buf.obs.shape == (5, 3, 4) and buf.actions.shape == (5, 3, 2) and buf.rewards.shape == (5, 3)
    batches = list(buf.minibatches(4, torch.Generator().manual_seed(0)))
    assert len(batches) == 4
    seen = torch.cat([b["obs"][:, 0] for b in batches])
    assert sorted(seen.tolist()) == sorted(buf.obs[..., 0].flatten().tolist())
    with pytest.raises(RuntimeError, match="full"):
        buf.add(
            obs, torch.zeros(3, 2), torch.zeros(3), torch.zeros(3), torch.zeros(3), torch.zeros(3, dtype=torch.bool)
        )
    with pytest.raises(ValueError, match="num_minibatches"):
        next(buf.minibatches(16, torch.Generator()))

import pytest
import torch

from roto.rl.normalizers import RunningStandardScaler


def test_batched_updates_equal_the_statistics_of_all_data():
    data = torch.randn(1000, 3, generator=torch.Generator().manual_seed(0), dtype=torch.float64) * 3 + 2
    scaler = RunningStandardScaler(3)
    for part in torch.split(data, [1, 99, 400, 500]):
        scaler.update(part)
    assert torch.allclose(scaler.mean, data.mean(0))
    assert torch.allclose(scaler.var, data.var(0, unbiased=False))
    assert scaler.count.item() == 1000


def test_forward_standardises_clips_and_inverts():
    scaler = RunningStandardScaler(1, clip=5.0)
    scaler.update(torch.tensor([[1.0], [3.0]]))  # mean 2, var 1
    assert scaler(torch.tensor([[4.0]])).item() == pytest.approx(2.0, rel=1e-6)
    assert scaler(torch.tensor([[100.0]])).item() == 5.0
    assert scaler.inverse(torch.tensor([[2.0]])).item() == pytest.approx(4.0, rel=1e-6)


def test_statistics_are_saved_with_the_module():
    scaler = RunningStandardScaler(2)
    scaler.update(torch.randn(10, 2))
    restored = RunningStandardScaler(2)
    restored.load_state_dict(scaler.state_dict())
    assert torch.equal(restored.mean, scaler.mean) and torch.equal(restored.var, scaler.var)

import pytest
import torch

import roto


@pytest.fixture(autouse=True)
def _one_torch_thread():
    torch.set_num_threads(1)


def make_env(task: str = "bounce", **kwargs):
    kwargs.setdefault("num_envs", 2)
    return roto.make(task, **kwargs)

"""Task rules on numpy arrays (the one-world step) against the same rules on torch tensors."""

import dataclasses

import numpy as np
import pytest
import torch

from roto.robots import get_robot
from roto.tasks import get_task
from roto.tasks.arrays import as_dtype_of, flip_rows, squared_norm, tanh, vector_norm, where
from roto.tasks.baoding import geometry_of
from roto.tasks.base import TaskInputs

B = 4000


def both(array):
    return array, torch.from_numpy(array.copy())


def assert_same(numpy_result, torch_result):
    assert isinstance(numpy_result, np.ndarray) and isinstance(torch_result, torch.Tensor)
    assert numpy_result.dtype == torch_result.numpy().dtype
    np.testing.assert_array_equal(numpy_result, torch_result.numpy())


@pytest.mark.parametrize("components", [2, 3])
def test_vector_norm_gives_the_same_bits_and_agrees_with_numpys_norm(components):
    v, t = both(np.random.default_rng(0).normal(size=(B, 2, components)) * 0.05)
    assert_same(vector_norm(v), vector_norm(t))
    np.testing.assert_allclose(vector_norm(v), np.linalg.norm(v, axis=-1), rtol=1e-15)
    np.testing.assert_array_equal(vector_norm(np.array([[3.0, 4.0]])), [5.0])


def test_tanh_where_and_dtype_give_the_same_bits():
    x, t = both(np.random.default_rng(1).normal(size=(B, 2)))
    assert_same(tanh(x), tanh(t))
    np.testing.assert_allclose(tanh(x), np.tanh(x), rtol=1e-15)
    mask, mask_t = both(x > 0)
    counts, counts_t = both(np.arange(2 * B).reshape(B, 2))
    assert_same(where(mask, 0, counts + 1), where(mask_t, 0, counts_t + 1))
    assert_same(where(mask, x, -x), where(mask_t, t, -t))
    assert_same(as_dtype_of(mask, x), as_dtype_of(mask_t, t))
    assert_same(flip_rows(x), flip_rows(t))
    np.testing.assert_array_equal(flip_rows(x)[0], x[-1])


def random_inputs(task_name, robot, rng):
    """Ball states near the task's targets (latches, swaps, drops and ends all occur) and contacts."""
    n_ball = 2 if task_name == "baoding" else 1
    centre = np.asarray(geometry_of(robot).targets) if task_name == "baoding" else np.array([[0.0, 0.0, 0.05]])
    pos = centre[None] + rng.normal(size=(B, n_ball, 3)) * rng.choice([0.004, 0.1], size=(B, 1, 1))
    return TaskInputs(pos, rng.normal(size=(B, n_ball, 3)), rng.random((B, n_ball)) < 0.5)


@pytest.mark.parametrize("task_name", ["bounce", "baoding"])
def test_a_task_steps_numpy_arrays_exactly_as_torch_tensors(task_name):
    task, robot, rng = get_task(task_name), get_robot("shadow"), np.random.default_rng(2)
    torch_state = task.init_state(robot, B, torch.device("cpu"))
    fields = [f.name for f in dataclasses.fields(torch_state)]
    numpy_state = type(torch_state)(**{name: getattr(torch_state, name).numpy().copy() for name in fields})
    ends = 0
    for _ in range(12):
        inputs = random_inputs(task_name, robot, rng)
        torch_inputs = TaskInputs(*(torch.from_numpy(np.copy(x)) for x in dataclasses.astuple(inputs)))
        got, expected = task.step(numpy_state, inputs), task.step(torch_state, torch_inputs)
        assert got.reward_terms.keys() == expected.reward_terms.keys()
        for name in got.reward_terms:
            assert_same(got.reward_terms[name], expected.reward_terms[name])
        assert_same(got.terminated, expected.terminated)
        for field in dataclasses.fields(torch_state):
            assert_same(getattr(numpy_state, field.name), getattr(torch_state, field.name))
        ends += int(expected.terminated.sum())
    metric = task.metrics(torch_state)[task.metric_names[0]]
    assert ends > 0 and metric.sum() > 0  # episode ends and counted events were compared


@pytest.mark.parametrize("components", [2, 3])
def test_squared_norm_gives_the_same_bits_without_torch(components):
    v, t = both(np.random.default_rng(3).normal(size=(B, 2, components)))
    assert_same(squared_norm(v), squared_norm(t))
    np.testing.assert_allclose(squared_norm(v), (v**2).sum(axis=-1), rtol=1e-15)


def test_atan2_gives_the_same_bits_and_agrees_with_numpys():
    from roto.tasks.arrays import atan2

    rng = np.random.default_rng(3)
    y, y_t = both(rng.normal(size=B))
    x, x_t = both(rng.normal(size=B))
    assert_same(atan2(y, x), atan2(y_t, x_t))
    np.testing.assert_allclose(atan2(y, x), np.arctan2(y, x), rtol=1e-14)


def test_zero_on_host_reads_numpy_and_cpu_tensors_only():
    from roto.tasks.arrays import zero_on_host

    assert zero_on_host(np.zeros(())) and not zero_on_host(np.full((), 0.25))
    assert zero_on_host(torch.zeros(())) and not zero_on_host(torch.tensor([0.0, 0.25]))


@pytest.mark.gpu
def test_zero_on_host_never_reads_a_device_tensor():
    from roto.tasks.arrays import zero_on_host

    assert not zero_on_host(torch.zeros((), device="cuda"))  # the caller's path that is right for any value

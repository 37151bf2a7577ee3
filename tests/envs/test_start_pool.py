"""The pool of episode starts: FIFO order, refills, checkpointing, and pooled resets against a
slow reference (the first frame rebuilt from the world's own state after the reset)."""

import pytest
import torch

from roto.envs.start_pool import StartPool
from roto.registry import list_envs
from tests.conftest import make_env


def counting_pool(size: int) -> tuple[StartPool, list[int]]:
    """A pool whose starts are consecutive integers (``x``) and their squares (``y``)."""
    drawn = [0]
    draws: list[int] = []

    def draw(n: int) -> dict[str, torch.Tensor]:
        draws.append(n)
        values = torch.arange(drawn[0], drawn[0] + n)
        drawn[0] += n
        return {"x": values, "y": values**2}

    return StartPool(draw, size), draws


def test_starts_come_out_in_order_across_refills():
    pool, draws = counting_pool(4)
    taken = [pool.take(n) for n in (3, 3, 1, 4, 0, 2)]
    assert torch.cat([t["x"] for t in taken]).tolist() == list(range(13))
    assert all(torch.equal(t["y"], t["x"] ** 2) for t in taken)
    assert draws == [4, 4, 4, 4]  # each refill draws the pool's size, leftovers go first
    assert pool.remaining == 3


def test_clear_drops_what_was_drawn():
    pool, _ = counting_pool(4)
    pool.take(1)
    pool.clear()
    assert pool.remaining == 0
    assert pool.take(2)["x"].tolist() == [4, 5]


def test_state_dict_round_trip_hands_out_the_same_leftovers():
    pool, _ = counting_pool(5)
    pool.take(2)
    saved = pool.state_dict()
    restored, _ = counting_pool(5)
    restored.load_state_dict(saved, torch.device("cpu"))
    assert restored.remaining == pool.remaining == 3
    assert torch.equal(restored.take(3)["x"], pool.take(3)["x"])


def test_bad_size_is_a_clear_error():
    with pytest.raises(ValueError, match="start pool size must be >= 1, got 0"):
        StartPool(lambda n: {}, 0)


def first_frame_from_world(env, world: int) -> dict[str, torch.Tensor]:
    """The slow reference: the reset world's first frame rebuilt from the backend's state of it."""
    qpos = torch.from_numpy(env.backend.qpos[world : world + 1].copy())
    qvel = torch.from_numpy(env.backend.qvel[world : world + 1].copy())
    target = env.joint_targets[world : world + 1]
    sensors = env.backend.sensors_at(qpos, qvel, target).to(torch.float64)
    selected = env.selections.select(qpos, qvel, sensors[:, None])
    task = env.task_state_frame()[world : world + 1]  # the world's task state, cleared by its reset
    return env.observation_frame(selected, target, torch.zeros(1, env.num_actions), task)


@pytest.mark.parametrize(("task", "robot"), list_envs())
def test_a_pooled_reset_shows_the_first_frame_of_the_state_it_wrote(task, robot):
    env = make_env(task, robot=robot, num_envs=4, obs_mode="state", extra_groups=("task",), seed=1)
    gen = torch.Generator().manual_seed(0)
    env.reset()
    resets = 0
    for _ in range(300):
        obs, _, terminated, truncated, _ = env.step(torch.rand(4, env.num_actions, generator=gen) * 2 - 1)
        for world in torch.nonzero(terminated | truncated).flatten().tolist():
            resets += 1
            expected = first_frame_from_world(env, world)
            assert env.backend.state[world, 0] == 0.0  # the world's clock restarted
            for name, frame in expected.items():
                stacked = obs[name][world].reshape(env.config.frame_stack, -1)
                assert torch.equal(stacked, frame.expand(env.config.frame_stack, -1)), name
        if resets >= 3:
            break
    assert resets >= 3, "random actions ended fewer than 3 episodes in 300 steps"
    env.close()


def test_env_checkpoint_mid_pool_continues_bit_identically():
    gen = torch.Generator().manual_seed(0)
    actions = torch.rand(300, 4, 20, generator=gen) * 2 - 1
    first = make_env("bounce", num_envs=4, seed=2)
    first.reset()
    cut = None
    for t, a in enumerate(actions):
        first.step(a)
        if 0 < first.starts.pool.remaining < first.starts.pool.size:  # cut where the pool is part-used
            cut = t + 1
            break
    assert cut is not None, "no reset left the pool part-used within 300 steps"
    second = make_env("bounce", num_envs=4, seed=0)
    second.reset()
    second.load_state_dict(first.state_dict())
    whole = make_env("bounce", num_envs=4, seed=2)
    whole.reset()
    reference = [whole.step(a)[0]["proprio"] for a in actions]
    resumed = [second.step(a)[0]["proprio"] for a in actions[cut:]]
    assert all(torch.equal(a, b) for a, b in zip(reference[cut:], resumed, strict=True))
    for env in (whole, first, second):
        env.close()


def test_seeded_reset_repeats_a_fresh_env():
    used = make_env("baoding", num_envs=3, seed=5)
    used.reset()
    for _ in range(20):
        used.step(torch.rand(3, 20) * 2 - 1)
    obs_used, _ = used.reset(seed=9)
    fresh = make_env("baoding", num_envs=3, seed=9)
    obs_fresh, _ = fresh.reset()
    for name in obs_fresh:
        assert torch.equal(obs_used[name], obs_fresh[name])
    used.close()
    fresh.close()

import pytest
import torch

from roto.rl.ssl.sequences import SequenceMemory, sequence_windows, split_windows


def rollout(steps=5, envs=2, start=0):
    """obs value = 10 * step + env (step counted from ``start``), actions = -obs."""
    t = torch.arange(start, start + steps, dtype=torch.float32)[:, None, None]
    b = torch.arange(envs, dtype=torch.float32)[None, :, None]
    obs = 10 * t + b
    return {"proprio": obs}, -obs.expand(steps, envs, 1)


def test_windows_skip_episode_ends_inside_but_allow_one_at_the_last_observation():
    obs, actions = rollout()
    dones = torch.zeros(5, 2, dtype=torch.bool)
    dones[1, 0] = True  # env 0's episode ends at step 1: obs 2 is a new episode's
    windows = sequence_windows(obs, actions, dones, 3)
    starts = windows["obs"]["proprio"][:, 0, 0].tolist()
    # env 1: starts 0, 1, 2; env 0: windows over steps 0-2 and 1-3 contain the end, 2-4 does not
    assert sorted(starts) == [1.0, 11.0, 20.0, 21.0]
    first = windows["obs"]["proprio"][starts.index(20.0), :, 0]
    assert first.tolist() == [20.0, 30.0, 40.0]
    assert windows["actions"].shape == (4, 3, 1)
    assert torch.equal(windows["actions"], -windows["obs"]["proprio"])
    with pytest.raises(ValueError, match="sequence length"):
        sequence_windows(obs, actions, dones, 1)


def test_split_windows_shuffles_into_equal_batches_and_respects_the_limit():
    obs, actions = rollout(steps=6, envs=3)
    windows = sequence_windows(obs, actions, torch.zeros(6, 3, dtype=torch.bool), 2)  # 15 windows
    batches = split_windows(windows, 4, torch.Generator().manual_seed(0))
    assert [len(b["actions"]) for b in batches] == [3, 3, 3, 3]
    seen = torch.cat([b["obs"]["proprio"][:, 0, 0] for b in batches]).tolist()
    assert len(set(seen)) == 12
    limited = split_windows(windows, 4, torch.Generator().manual_seed(0), limit=9)
    assert [len(b["actions"]) for b in limited] == [2, 2, 2, 2]


def test_memory_keeps_windows_across_rollouts_and_drops_the_oldest():
    memory = SequenceMemory(capacity=10, length=3)
    dones = torch.zeros(4, 2, dtype=torch.bool)
    obs, actions = rollout(steps=4, envs=2, start=0)
    memory.add_rollout(obs, actions, dones)  # starts 0, 1: 4 windows
    assert memory.count == 4
    obs, actions = rollout(steps=4, envs=2, start=4)
    memory.add_rollout(obs, actions, dones)  # tail steps 2, 3 + 4 new steps: starts 2..5, 8 windows
    assert memory.count == 10 and memory.head == 2
    starts = sorted(memory.contents()["obs"]["proprio"][:, 0, 0].tolist())
    # the first rollout's two oldest windows (start 0) were overwritten; windows starting at
    # steps 2 and 3 span both rollouts
    assert starts == [10.0, 11.0, 20.0, 21.0, 30.0, 31.0, 40.0, 41.0, 50.0, 51.0]


def test_memory_state_round_trips():
    memory = SequenceMemory(capacity=6, length=2)
    obs, actions = rollout()
    memory.add_rollout(obs, actions, torch.zeros(5, 2, dtype=torch.bool))
    copy = SequenceMemory(capacity=6, length=2)
    copy.load_state_dict(memory.state_dict())
    assert (copy.head, copy.count) == (memory.head, memory.count)
    assert torch.equal(copy.contents()["actions"], memory.contents()["actions"])
    with pytest.raises(RuntimeError, match="empty"):
        SequenceMemory(capacity=6, length=2).contents()

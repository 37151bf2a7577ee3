"""The event recorder keeps, for every rise of the headline metric in an episode older than
``lead`` steps, the state ``lead`` steps back: checked against a per-world Python loop."""

import pytest
import torch

from roto.envs.aids.event_recorder import EventRecorder, RecordedEvents
from roto.envs.aids.replayed_starts import ReplayedStarts

B, NQ = 3, 2


def rows_at(step: int) -> dict[str, torch.Tensor]:
    """World w's state at ``step``: values 100 * w + step (so every state names its world and step),
    and a task field true in every world but the first."""
    base = torch.arange(B, dtype=torch.float64)[:, None] * 100 + step
    first = torch.arange(B) == 0
    return {"qpos": base.expand(B, NQ).clone(), "qvel": base.clone(), "target": base.clone(), "task/x": ~first}


def reference(events, dones, lead, capacity):
    """The states the recorder should hold, oldest first, by a loop over steps and worlds."""
    length, recorded = [0] * B, []
    for step, (event, done) in enumerate(zip(events, dones, strict=True)):
        for w in range(B):
            length[w] += 1
            if event[w] and length[w] > lead:
                recorded.append(100 * w + step - lead)
            if done[w]:
                length[w] = 0
    return recorded[-capacity:]


def drive(recorder, events, dones):
    length = torch.zeros(B, dtype=torch.int64)
    metric = torch.zeros(B)
    for step, (event, done) in enumerate(zip(events, dones, strict=True)):
        length += 1
        metric = metric + torch.tensor(event, dtype=torch.float32)
        recorder.observe(rows_at(step), metric, length, torch.tensor(done))
        metric = metric.masked_fill(torch.tensor(done), 0.0)
        length = length.masked_fill(torch.tensor(done), 0)


def held_states(recorder):
    """The recorded states' step values, oldest first (the bank is a ring)."""
    bank, held = recorder.as_bank(("x",))
    n, capacity = int(held), recorder.capacity
    order = [(int(recorder.recorded) - n + k) % capacity for k in range(n)]
    return [float(bank.qvel[i]) for i in order], bank


@pytest.mark.parametrize("capacity", [64, 4])
def test_recorded_states_are_those_lead_steps_before_each_event_of_the_same_episode(capacity):
    gen = torch.Generator().manual_seed(0)
    steps, lead = 60, 3
    events = (torch.rand(steps, B, generator=gen) < 0.3).tolist()
    dones = (torch.rand(steps, B, generator=gen) < 0.1).tolist()
    recorder = EventRecorder.empty(lead, capacity, rows_at(0))
    drive(recorder, events, dones)
    want = reference(events, dones, lead, capacity)
    got, bank = held_states(recorder)
    assert got == want and len(want) == min(capacity, int(recorder.recorded)) > 0
    for i in range(int(recorder.held())):  # every field of a row is the same world's same step
        assert torch.equal(bank.qpos[i], bank.qvel[i].expand(NQ)) and bank.target[i] == bank.qvel[i]
        assert bool(bank.task["x"][i]) == bool(bank.qvel[i] >= 100)


def test_an_event_too_early_in_its_episode_records_nothing():
    recorder = EventRecorder.empty(5, 8, rows_at(0))
    events = [[False] * B for _ in range(5)] + [[True] * B]  # at length 6: recorded
    events[2] = [True] * B  # at length 3: the state 5 steps back is not this episode's
    drive(recorder, events, [[False] * B] * 6)
    assert int(recorder.recorded) == B and held_states(recorder)[0] == [0.0, 100.0, 200.0]


def test_a_restored_recorder_records_as_the_original():
    gen = torch.Generator().manual_seed(1)
    events = (torch.rand(40, B, generator=gen) < 0.3).tolist()
    dones = (torch.rand(40, B, generator=gen) < 0.1).tolist()
    first = EventRecorder.empty(2, 16, rows_at(0))
    drive(first, events[:20], dones[:20])
    second = EventRecorder.from_state_dict(first.state_dict(), torch.device("cpu"))
    drive(first, events[20:], dones[20:])
    drive(second, events[20:], dones[20:])
    assert all(torch.equal(first.bank[k], second.bank[k]) for k in first.bank)


def test_lead_and_capacity_below_one_are_refused():
    with pytest.raises(ValueError, match="lead >= 1 and capacity >= 1, got 0, 8"):
        EventRecorder.empty(0, 8, rows_at(0))


# ---------------------------------------------------------------- in an env (scripted Bounce)

LEAD, STEPS, WORLDS = 3, 160, 8


def own_bank(path):
    """A bank of Bounce starts (the task's own, at rest) in the Shadow's scene."""
    import numpy as np

    import roto

    env = roto.make("bounce", robot="shadow", num_envs=4, seed=0)
    env.reset()
    np.savez(path, physics=env.backend.physics_state(), target=env.joint_targets.numpy(), robot="shadow")
    env.close()
    return str(path)


def recording_env(bank, share=0.5, **kwargs):
    import roto

    aids = {"replayed_starts": {"bank": bank, "share": share, "record_lead": LEAD}}
    return roto.make("bounce", robot="shadow", obs_mode="state", num_envs=WORLDS, aids=aids, **{"seed": 1, **kwargs})


def play(env, steps, logs=None):
    """The scripted Bounce policy for ``steps`` steps; with ``logs``, every step's qpos (before
    resets), bounces so far and done flags appended to it."""
    from roto.scripted import ScriptedBounce

    policy, task = ScriptedBounce(env), env.task
    if logs is not None:
        backend_step = env.backend.step

        def logged_step(ctrl):
            sim = backend_step(ctrl)
            logs["qpos"].append(sim.qpos.clone())
            return sim

        class LoggedTask:  # the task, with its counters read after every step
            def __getattr__(self, name):
                return getattr(task, name)

            def step(self, state, inputs):
                result = task.step(state, inputs)
                logs["bounces"].append(state.bounces.clone())
                return result

        env.backend.step, env.task = logged_step, LoggedTask()
    obs, _ = env.reset()
    for _ in range(steps):
        obs, _, terminated, truncated, _ = env.step(policy(obs))
        policy.reset(terminated | truncated)
        if logs is not None:
            logs["done"].append(terminated | truncated)


def test_an_env_records_its_own_states_lead_steps_before_each_bounce(tmp_path):
    env = recording_env(own_bank(tmp_path / "bank.npz"))
    logs = {"qpos": [], "bounces": [], "done": []}
    play(env, STEPS, logs)
    expected, length, last = [], [0] * WORLDS, [0] * WORLDS  # the slow reference: a loop per world
    for t in range(STEPS):
        for w in range(WORLDS):
            length[w] += 1
            if logs["bounces"][t][w] > last[w] and length[w] > LEAD:
                expected.append(logs["qpos"][t - LEAD][w])
            last[w] = 0 if logs["done"][t][w] else int(logs["bounces"][t][w])
            length[w] = 0 if logs["done"][t][w] else length[w]
    bank, held = env.aid(RecordedEvents).recorder.as_bank(())
    assert int(held) == len(expected) > 10
    for k, qpos in enumerate(expected):
        assert torch.equal(bank.qpos[k], qpos)
    starts = env.starts.draw(256)
    replayed = starts["qpos"][starts["replayed"]]
    file_states = env.aid(ReplayedStarts).bank.qpos
    own = [(bank.qpos[: int(held)] == q).all(dim=1).any() for q in replayed]
    mine = [(file_states == q).all(dim=1).any() for q in replayed]
    assert all(a or b for a, b in zip(own, mine, strict=True)) and any(own) and any(mine)
    env.close()


def test_a_resumed_env_records_and_draws_as_the_original(tmp_path):
    bank = own_bank(tmp_path / "bank.npz")
    first = recording_env(bank, share=0.9)
    play(first, 100)
    saved = first.state_dict()
    second = recording_env(bank, share=0.9, seed=7)
    second.load_state_dict(saved)
    assert int(second.aid(RecordedEvents).recorder.recorded) == int(first.aid(RecordedEvents).recorder.recorded) > 0
    gen = torch.Generator().manual_seed(2)
    for _ in range(60):
        action = torch.rand(WORLDS, first.num_actions, generator=gen) * 2 - 1
        obs_a, *_ = first.step(action)
        obs_b, *_ = second.step(action)
        assert all(torch.equal(obs_a[k], obs_b[k]) for k in obs_a)
    assert torch.equal(first.starts.draw(32)["qpos"], second.starts.draw(32)["qpos"])


def test_a_resumed_env_draws_its_starts_when_the_original_does_from_the_states_recorded_by_then(tmp_path):
    """Saved with a pool too small for every world to reset: loading must not top it up, or the
    resumed env would draw from fewer recorded states than the original later does."""
    from roto.scripted import ScriptedBounce

    first = recording_env(own_bank(tmp_path / "bank.npz"), share=0.9)
    policy = ScriptedBounce(first)
    obs, _ = first.reset()
    for _ in range(400):  # the scripted policy bounces: events to record; drops: resets
        obs, _, terminated, truncated, _ = first.step(policy(obs))
        policy.reset(terminated | truncated)
        if 0 < first.starts.pool.remaining < WORLDS and first.aid(RecordedEvents).recorder.recorded > 0:
            break
    assert 0 < first.starts.pool.remaining < WORLDS
    second = recording_env(own_bank(tmp_path / "other.npz"), share=0.9, seed=7)
    second.load_state_dict(first.state_dict())
    recorded, drew_after_new_states = int(first.aid(RecordedEvents).recorder.recorded), False
    for _ in range(600):
        left, action = first.starts.pool.remaining, policy(obs)
        obs, _, terminated, truncated, _ = first.step(action)
        obs_b, *_ = second.step(action)
        assert all(torch.equal(obs[k], obs_b[k]) for k in obs)
        policy.reset(terminated | truncated)
        drew_after_new_states |= (
            first.starts.pool.remaining > left and int(first.aid(RecordedEvents).recorder.recorded) > recorded
        )
    assert drew_after_new_states
    assert torch.equal(
        first.aid(RecordedEvents).recorder.bank["qpos"], second.aid(RecordedEvents).recorder.bank["qpos"]
    )


def test_recording_needs_replayed_starts_and_evaluation_never_records():
    from roto.envs.config import EnvConfig
    from roto.rl.run_spec import RunSpec

    with pytest.raises(
        ValueError, match=r"record_lead 10 records states for replayed starts, but aids.replayed_starts.share"
    ):
        EnvConfig(task="baoding", aids={"replayed_starts": {"bank": "b.npz", "share": 0.0, "record_lead": 10}})
    with pytest.raises(ValueError, match=r"aids\.replayed_starts\.record_capacity must be an integer >= 1, got 0"):
        EnvConfig(task="baoding", aids={"replayed_starts": {"bank": "b.npz", "record_capacity": 0}})
    config = EnvConfig(task="bounce", aids={"replayed_starts": {"bank": "bank.npz", "share": 0.5, "record_lead": 10}})
    assert RunSpec(env=config).eval_env_config(4).aids.replayed_starts is None


def test_a_reset_mid_run_starts_every_metric_over(tmp_path):
    env = recording_env(own_bank(tmp_path / "bank.npz"))
    play(env, 80)
    assert env.aid(RecordedEvents).recorder.last_metric.any()  # some episode has bounced
    env.reset()
    assert not env.aid(RecordedEvents).recorder.last_metric.any()
    env.close()

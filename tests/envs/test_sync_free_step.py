"""The sync-free step (what a GPU env runs: masked resets every step, host reads every few steps)
against the CPU step it replaces, on the CPU where both can run; and, on a GPU, that the step never
waits for the device."""

import pytest
import torch

import roto
from roto.envs.aids.event_recorder import RecordedEvents
from roto.envs.aids.tolerance import ToleranceAid
from roto.registry import list_envs
from tests.conftest import BAODING_AIDS, require_warp

RECIPE = {**BAODING_AIDS, "extra_groups": ("privileged", "task")}
"""The Baoding recipes' training aids and the groups their critic reads: what a GPU training env of
those recipes steps."""


def rollout(env, steps: int, seed: int = 0, after_step=None) -> tuple[list[torch.Tensor], int]:
    """Everything the env hands out over ``steps`` random-action steps, and how many episodes ended;
    ``after_step(t)``, if given, runs after the reset (t = -1) and after each step t (0-based)."""
    generator = torch.Generator(device=env.device).manual_seed(seed)
    obs, _ = env.reset(seed=seed)
    if after_step is not None:
        after_step(-1)
    seen, finished = [torch.cat([v.flatten() for v in obs.values()])], 0
    for t in range(steps):
        action = torch.rand(env.num_envs, env.num_actions, generator=generator, device=env.device) * 2 - 1
        obs, reward, terminated, truncated, info = env.step(action)
        done = terminated | truncated
        finished += int(done.sum())
        seen += [torch.cat([v.flatten() for v in obs.values()]), reward, done.float()]
        if "episode" in info and bool(info["_episode"].any()):  # a sync-free step always has the keys
            mask = info["_episode"]
            seen += [info["episode"]["r"][mask], info["final_obs"]["proprio"][mask].flatten()]
        if after_step is not None:
            after_step(t)
    return seen, finished


def sync_free(env, check_every: int):
    env.checks.go_sync_free(check_every)
    return env


@pytest.mark.parametrize(("task", "robot"), [("bounce", "shadow"), ("baoding", "allegro")])
def test_sync_free_step_is_bit_identical_to_the_cpu_step(task, robot):
    reference = roto.make(task, robot=robot, num_envs=6, seed=1)
    candidate = sync_free(roto.make(task, robot=robot, num_envs=6, seed=1), check_every=3)
    (a, finished), (b, _) = rollout(reference, 150), rollout(candidate, 150)
    assert finished > 5, "too few episodes ended: the masked reset went untested"
    assert len(a) == len(b) and all(torch.equal(x, y) for x, y in zip(a, b, strict=True))


def test_sync_free_step_has_a_start_for_every_world_ending_on_every_step():
    # its pool is read only every check_every steps: from a reset on it must cover every world
    # ending on each of them (a pool run dry hands its last row out again, then raises)
    env = sync_free(roto.make("bounce", num_envs=3, seed=0), check_every=3)
    env.reset(seed=0)
    starts = []
    for _ in range(7):
        qpos = torch.from_numpy(env.backend.qpos.copy())
        qpos[:, env.indices.ball_pos.index[0, 2]] = -0.5  # every ball far below the palm: every world ends
        env.backend.set_state(torch.arange(3), qpos, torch.zeros(3, env.model.nv))
        _, _, terminated, _, _ = env.step(torch.zeros(3, env.num_actions))
        assert terminated.all()
        starts.append(torch.from_numpy(env.backend.qpos.copy()))
    every = torch.cat(starts)
    assert len(torch.unique(every, dim=0)) == len(every), "a start was handed out twice"


def test_sync_free_step_with_the_baoding_training_aids_is_bit_identical_to_the_cpu_step():
    # a replayed start drawn from the states the env records depends on when it is drawn: the CPU
    # step draws when a reset runs short, the sync-free step tops its pool up after its reset and
    # every check_every steps, so here the CPU step's pool is topped up then too
    reference = roto.make("baoding", robot="shadow", num_envs=6, seed=1, **RECIPE)
    reference.checks.every = 3  # on the CPU step this sizes only the pool reset() fills

    def top_up(t: int) -> None:
        if t == -1 or (t + 1) % 3 == 0:
            reference.starts.pool.ensure(3 * reference.num_envs)

    candidate = sync_free(roto.make("baoding", robot="shadow", num_envs=6, seed=1, **RECIPE), check_every=3)
    (a, finished), (b, _) = rollout(reference, 150, after_step=top_up), rollout(candidate, 150)
    assert finished > 5, "too few episodes ended: the masked reset went untested"
    assert len(a) == len(b) and all(torch.equal(x, y) for x, y in zip(a, b, strict=True))
    assert int(reference.aid(RecordedEvents).recorder.recorded) > 0, (
        "no state was recorded: the recorded bank went untested"
    )
    assert torch.equal(reference.aid(RecordedEvents).recorder.recorded, candidate.aid(RecordedEvents).recorder.recorded)
    assert torch.equal(reference.aid(ToleranceAid).curriculum.mean, candidate.aid(ToleranceAid).curriculum.mean)


def test_sync_free_step_reports_a_non_finite_action_at_the_next_check():
    env = sync_free(roto.make("bounce", num_envs=2), check_every=3)
    env.reset(seed=0)
    bad = torch.zeros(2, env.num_actions)
    bad[1, 0] = float("nan")
    env.step(bad)  # not read yet
    env.step(torch.zeros(2, env.num_actions))
    with pytest.raises(ValueError, match=r"non-finite values \(NaN or inf\) in the last 3 steps"):
        env.step(torch.zeros(2, env.num_actions))
    env.step(torch.zeros(2, env.num_actions))  # the flag was cleared with the error


def test_sync_free_state_dict_resumes_exactly():
    whole = sync_free(roto.make("bounce", num_envs=4, seed=2), check_every=5)
    rollout(whole, 40)
    part = sync_free(roto.make("bounce", num_envs=4, seed=2), check_every=5)
    rollout(part, 40)
    resumed = sync_free(roto.make("bounce", num_envs=4, seed=2), check_every=5)
    resumed.load_state_dict(part.state_dict())
    action = torch.full((4, whole.num_actions), 0.3)
    for _ in range(60):
        a, b = whole.step(action), resumed.step(action)
        assert all(torch.equal(a[0][k], b[0][k]) for k in a[0]) and torch.equal(a[1], b[1])


@pytest.mark.parametrize(
    ("task", "robot", "aids"), [("bounce", "shadow", {}), ("baoding", "shadow", RECIPE)], ids=["bounce", "aids"]
)
def test_sync_free_warp_step_reads_nothing_back_outside_its_periodic_checks(task, robot, aids, host_reads):
    # what a GPU env runs, on Warp's CPU device: every host read must be a deliberate one
    require_warp()
    env = sync_free(roto.make(task, robot=robot, num_envs=4, backend="warp", device="cpu", seed=0, **aids), 5)
    env.reset(seed=0)
    generator = torch.Generator().manual_seed(0)
    ended = torch.zeros((), dtype=torch.int64)
    with host_reads:
        for _ in range(40):
            _, _, terminated, truncated, _ = env.step(torch.rand(4, env.num_actions, generator=generator) * 2 - 1)
            ended += (terminated | truncated).sum()
    assert host_reads.seen == [], f"host reads outside the periodic checks: {sorted(set(host_reads.seen))}"
    assert int(ended) > 0, "no episode ended: the masked reset went untested"
    env.close()


cuda = pytest.mark.skipif(not torch.cuda.is_available(), reason="needs an NVIDIA GPU")


@pytest.mark.gpu
@cuda
@pytest.mark.parametrize(
    ("task", "robot", "aids"),
    [(t, r, {}) for t, r in list_envs()] + [("baoding", "shadow", RECIPE)],
    ids=[f"{t}-{r}" for t, r in list_envs()] + ["baoding-shadow-training_aids"],
)
def test_gpu_step_never_waits_for_the_device(task, robot, aids):
    env = roto.make(task, robot=robot, num_envs=1024, backend="warp", device="cuda", seed=0, **aids)
    env.reset(seed=0)
    generator = torch.Generator(device="cuda").manual_seed(0)
    finished = torch.zeros((), dtype=torch.int64, device="cuda")
    torch.cuda.set_sync_debug_mode("error")  # any wait outside the periodic checks raises
    try:
        for _ in range(300):
            action = torch.rand(1024, env.num_actions, generator=generator, device="cuda") * 2 - 1
            obs, reward, terminated, truncated, _ = env.step(action)
            finished += (terminated | truncated).sum()
    finally:
        torch.cuda.set_sync_debug_mode(0)
    assert int(finished) > 0
    assert all(bool(torch.isfinite(v).all()) for v in obs.values()) and bool(torch.isfinite(reward).all())
    env.close()

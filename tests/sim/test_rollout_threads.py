"""RolloutThreads against one plain single-thread ``rollout`` call over the whole batch (the reference)."""

from __future__ import annotations

import gc
import multiprocessing

import mujoco
import numpy as np
import pytest
from mujoco import rollout

from roto.robots import get_robot
from roto.sim.rollout_threads import RolloutThreads, chunk_ends, chunk_sizes
from roto.sim.scene import build_scene
from roto.tasks.bounce import BALL

_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS.value
_CTRL = mujoco.mjtState.mjSTATE_CTRL.value


@pytest.fixture(scope="module")
def batch() -> tuple[mujoco.MjModel, np.ndarray, np.ndarray]:
    """Allegro with a ball; 13 worlds with different joint offsets and random targets held 3 steps."""
    model, layout = build_scene(get_robot("allegro"), (BALL,))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    states = []
    for _ in range(13):
        data.qpos[:] = layout.default_qpos
        data.qpos[layout.act_qpos] += rng.uniform(-0.1, 0.1, len(layout.act_qpos))
        data.qpos[layout.ball_qpos[0] + 2] = 0.06  # the ball just above the palm: contacts in some worlds
        state = np.zeros(mujoco.mj_stateSize(model, _FULL))
        mujoco.mj_getState(model, data, state, _FULL)
        states.append(state)
    ctrl = rng.uniform(layout.ctrl_lo, layout.ctrl_hi, (13, 3, model.nu))
    return model, np.stack(states), ctrl


def _outputs(model: mujoco.MjModel, ctrl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Zeroed (state, sensordata) output arrays for controls ``ctrl`` (n, nstep, nu)."""
    n, nstep = ctrl.shape[:2]
    return np.zeros((n, nstep, mujoco.mj_stateSize(model, _FULL))), np.zeros((n, nstep, model.nsensordata))


def _reference(model: mujoco.MjModel, state0: np.ndarray, ctrl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n, nstep = ctrl.shape[:2]
    state, sensordata = _outputs(model, ctrl)
    rollout.Rollout(nthread=0).rollout(
        [model] * n,
        [mujoco.MjData(model)],
        state0,
        ctrl,
        control_spec=_CTRL,
        nstep=nstep,
        state=state,
        sensordata=sensordata,
    )
    return state, sensordata


@pytest.mark.parametrize(
    ("threads", "min_chunk", "run_threads"),
    [(1, 1, None), (1, 4, None), (2, 1, None), (2, 5, None), (3, 2, None), (2, 100, None), (3, 1, 2), (2, 1, 1)],
)
def test_matches_one_single_thread_rollout(batch, threads: int, min_chunk: int, run_threads: int | None) -> None:
    model, state0, ctrl = batch
    expected_state, expected_sensors = _reference(model, state0, ctrl)
    pool = RolloutThreads(model, threads, min_chunk)
    try:
        for _ in range(3):  # reuse of the helpers across calls
            state = np.full_like(expected_state, np.nan)
            sensordata = np.full_like(expected_sensors, np.nan)
            pool.run(state0, ctrl, state, sensordata, nstep=3, threads=run_threads)
            np.testing.assert_array_equal(state, expected_state)
            np.testing.assert_array_equal(sensordata, expected_sensors)
    finally:
        pool.close()


def test_an_error_reaches_the_caller_and_the_pool_stays_usable(batch) -> None:
    model, state0, ctrl = batch
    pool = RolloutThreads(model, 2, 2)
    try:
        state, sensordata = _outputs(model, ctrl)
        with pytest.raises(ValueError, match=r"state\.size"):
            pool.run(state0, ctrl, state[:, :2], sensordata, nstep=3)  # room for 2 steps, 3 asked for
        pool.run(state0, ctrl, state, sensordata, nstep=3)
        np.testing.assert_array_equal(state, _reference(model, state0, ctrl)[0])
    finally:
        pool.close()


def test_close_is_idempotent_and_final(batch) -> None:
    model, state0, ctrl = batch
    pool = RolloutThreads(model, 2, 4)
    helpers = list(pool._helpers)
    assert helpers and all(helper.is_alive() for helper in helpers)
    pool.close()
    pool.close()
    assert not any(helper.is_alive() for helper in helpers)
    with pytest.raises(RuntimeError, match="closed"):
        pool.run(state0, ctrl, *_outputs(model, ctrl), nstep=3)


def test_a_dropped_pool_stops_its_helpers(batch) -> None:
    model, state0, ctrl = batch
    pool = RolloutThreads(model, 3, 2)
    pool.run(state0, ctrl, *_outputs(model, ctrl), nstep=3)
    helpers = list(pool._helpers)
    del pool
    gc.collect()
    for helper in helpers:
        helper.join(timeout=10)
    assert not any(helper.is_alive() for helper in helpers)


def _run_in_child(pool: RolloutThreads, state0: np.ndarray, ctrl: np.ndarray, conn) -> None:
    state, sensordata = _outputs(pool.model, ctrl)
    pool.run(state0, ctrl, state, sensordata, nstep=ctrl.shape[1])
    conn.send(state)


def test_a_forked_child_starts_its_own_helpers(batch) -> None:
    model, state0, ctrl = batch
    expected_state, _ = _reference(model, state0, ctrl)
    pool = RolloutThreads(model, 2, 2)
    try:
        context = multiprocessing.get_context("fork")
        receive, send = context.Pipe(duplex=False)
        child = context.Process(target=_run_in_child, args=(pool, state0, ctrl, send), daemon=True)
        child.start()
        try:
            assert receive.poll(60), "the forked child did not finish its rollout"
            np.testing.assert_array_equal(receive.recv(), expected_state)
            child.join(timeout=10)
            assert child.exitcode == 0
        finally:
            if child.is_alive():
                child.kill()
    finally:
        pool.close()


def test_bad_settings_are_refused(batch) -> None:
    model = batch[0]
    with pytest.raises(ValueError, match="threads must be >= 1, got 0"):
        RolloutThreads(model, 0, 4)
    with pytest.raises(ValueError, match="min_chunk must be >= 1, got 0"):
        RolloutThreads(model, 2, 0)


def test_guided_chunks_shrink_to_the_minimum_and_cover_every_world_once() -> None:
    assert chunk_sizes(256, 1) == [256]  # one rollout call on the calling thread
    assert chunk_sizes(256, 2)[:4] == [64, 48, 36, 27]  # a quarter of what is left, then less
    assert chunk_sizes(256, 2)[-3:] == [1, 1, 1]
    assert chunk_sizes(13, 2, min_chunk=5) == [5, 5, 3]
    assert chunk_sizes(0, 2) == []
    for worlds, threads, min_chunk in [(256, 2, 1), (4096, 4, 2), (7, 3, 1), (1, 2, 1), (100, 2, 100)]:
        sizes = chunk_sizes(worlds, threads, min_chunk)
        assert sum(sizes) == worlds and all(size >= 1 for size in sizes)
        assert sizes == sorted(sizes, reverse=True)
        assert all(size >= min(min_chunk, worlds) for size in sizes[:-1])
        assert chunk_ends(worlds, threads, min_chunk)[-1] == worlds


def test_a_run_limited_to_one_thread_wakes_no_helper(batch, monkeypatch) -> None:
    model, state0, ctrl = batch
    pool = RolloutThreads(model, 2, 1)
    try:
        used = set()
        work = pool.work

        def recording_work(thread: int) -> None:
            used.add(thread)
            work(thread)

        monkeypatch.setattr(pool, "work", recording_work)
        pool.run(state0, ctrl, *_outputs(model, ctrl), nstep=3, threads=1)
        assert used == {0}
        pool.run(state0, ctrl, *_outputs(model, ctrl), nstep=3)
        assert used == {0, 1}
    finally:
        pool.close()

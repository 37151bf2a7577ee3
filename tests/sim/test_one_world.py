"""OneWorldStep and the one-world CPU backend against ``rollout`` (the reference)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
import torch
from mujoco import rollout

from roto.robots import get_robot
from roto.sim.mujoco_cpu import MujocoCpuBackend
from roto.sim.one_world import OneWorldStep
from roto.sim.scene import build_scene
from roto.tasks.baoding import baoding_balls, geometry_of

_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS.value
_CTRL = mujoco.mjtState.mjSTATE_CTRL.value
SUBSTEPS = 4
REST = ((0.0577, -0.0079, -0.0066), (0.0243, 0.0073, 0.0028))
"""Where the Shadow's two dropped Baoding balls come to rest (``roto.tasks.baoding.rest_after_drop``)."""


@pytest.fixture(scope="module")
def scene():
    """Shadow holding two Baoding balls just above the palm (contacts from the first steps)."""
    robot = get_robot("shadow")
    model, layout = build_scene(robot, baoding_balls(geometry_of(robot).ball_radius))
    data = mujoco.MjData(model)
    data.qpos[:] = layout.default_qpos
    for adr, rest in zip(layout.ball_qpos, REST, strict=True):
        data.qpos[adr : adr + 3] = np.asarray(rest) + np.array([0.0, 0.0, 0.004])
    state = np.zeros(mujoco.mj_stateSize(model, _FULL))
    mujoco.mj_getState(model, data, state, _FULL)
    return model, layout, state


def rollout_step(model, state, ctrl):
    """One control step by ``rollout``: (new state (nstate,), sensordata (substeps, nsensordata))."""
    states = np.zeros((1, SUBSTEPS, len(state)))
    sensors = np.zeros((1, SUBSTEPS, model.nsensordata))
    controls = np.repeat(ctrl[None, None], SUBSTEPS, axis=1)
    rollout.Rollout(nthread=0).rollout(
        [model], [mujoco.MjData(model)], state[None], controls, control_spec=_CTRL, nstep=SUBSTEPS, state=states,
        sensordata=sensors,
    )  # fmt: skip
    return states[0, -1], sensors[0]


def test_steps_match_rollout_bit_for_bit_through_contacts(scene):
    model, layout, state0 = scene
    stepper = OneWorldStep(model, SUBSTEPS)
    rng = np.random.default_rng(0)
    state, reference = state0.copy(), state0.copy()
    touched = 0
    for _ in range(200):
        ctrl = rng.uniform(layout.ctrl_lo, layout.ctrl_hi)
        sensors = np.full((SUBSTEPS, model.nsensordata), np.nan)
        assert stepper.step(state, ctrl, sensors)
        reference, expected_sensors = rollout_step(model, reference, ctrl)
        np.testing.assert_array_equal(state, reference)
        np.testing.assert_array_equal(sensors, expected_sensors)
        touched += np.any(expected_sensors != 0.0)
    assert touched > 100  # contacts (touch and force sensors) were part of what was compared


def test_a_world_that_mujoco_resets_is_left_untouched(scene):
    model, _, state0 = scene
    state = state0.copy()
    qvel = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_TIME.value) + model.nq
    state[qvel] = 1e12  # beyond MuJoCo's limit: it resets the world
    before = state.copy()
    assert not OneWorldStep(model, SUBSTEPS).step(state, np.zeros(model.nu), np.zeros((SUBSTEPS, model.nsensordata)))
    np.testing.assert_array_equal(state, before)


def test_one_world_backend_matches_the_rollout_path_including_a_reset_world(scene):
    model, layout, state0 = scene
    one = MujocoCpuBackend(model, 1, substeps=SUBSTEPS)
    two = MujocoCpuBackend(model, 2, substeps=SUBSTEPS)  # steps through rollout
    one.load_physics_state(state0[None])
    two.load_physics_state(np.stack([state0, state0]))
    rng = np.random.default_rng(1)
    for t in range(30):
        if t == 20:  # make world 0 blow up in both
            qvel = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_TIME.value) + model.nq
            one.state[0, qvel] = two.state[0, qvel] = 1e12
        ctrl = rng.uniform(layout.ctrl_lo, layout.ctrl_hi, (1, model.nu))
        diverged_one = one.step_array(ctrl)
        diverged_two = two.step_array(np.concatenate([ctrl, ctrl]))
        assert diverged_one.tolist() == [t == 20] and diverged_two[0] == diverged_one[0]
        np.testing.assert_array_equal(one.state[0], two.state[0])
        np.testing.assert_array_equal(one.sensordata[0], two.sensordata[0])
    one.close()
    two.close()


def test_sensors_at_one_state_match_the_same_state_in_a_batch(scene):
    model, layout, state0 = scene
    backend = MujocoCpuBackend(model, 2, substeps=SUBSTEPS)
    qpos0 = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_TIME.value)
    qpos = torch.from_numpy(np.stack([state0[qpos0 : qpos0 + model.nq]] * 2))
    qpos[1, layout.act_qpos] += 0.05
    qvel = torch.zeros(2, model.nv, dtype=torch.float64)
    ctrl = torch.from_numpy(np.stack([layout.ctrl_lo, layout.ctrl_hi]))
    batch = backend.sensors_at(qpos, qvel, ctrl)
    for i in range(2):
        single = backend.sensors_at(qpos[i : i + 1], qvel[i : i + 1], ctrl[i : i + 1])
        torch.testing.assert_close(single, batch[i : i + 1], rtol=0, atol=0)
    assert batch.abs().sum() > 0
    backend.close()

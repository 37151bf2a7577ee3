"""One world's control step with plain ``mj_step`` on a persistent ``MjData``: the one-world fast path.

For a single world, ``RolloutThreads`` (locks, chunk bookkeeping, the ``rollout`` call's argument
checks) costs tens of microseconds a step beside some 150 of physics, which is what a one-world
Gymnasium env pays in full. ``OneWorldStep`` does what ``rollout`` does for one world and one
control held for ``substeps`` steps: set the full physics state, zero the warm start, step, and
record each substep's sensor values; the results are bit-identical to ``rollout``'s
(tests/sim/test_one_world.py). ``rollout`` stops stepping a world at MuJoCo's first warning (a
state gone non-finite or huge, which also resets the world; a full contact buffer); a step that
raised one is reported as not done, so that the caller can step it with ``rollout`` itself, whose
handling of such worlds is the reference.
"""

from __future__ import annotations

import mujoco
import numpy as np

_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS.value


class OneWorldStep:
    """``substeps`` physics steps of one world of ``model``, in place on its state vector (the
    model's mocap bodies, applied forces and equality constraints left at their defaults, as
    ``rollout`` leaves them)."""

    def __init__(self, model: mujoco.MjModel, substeps: int) -> None:
        self.model = model
        self.substeps = substeps
        self._data = mujoco.MjData(model)
        # views of the data's arrays, made once (each attribute access makes a new numpy wrapper)
        self._ctrl, self._sensors = self._data.ctrl, self._data.sensordata
        self._warmstart = self._data.qacc_warmstart
        self._warnings = self._data.warning.number  # (mjNWARNING,) warning counters

    def step(self, state: np.ndarray, ctrl: np.ndarray, sensordata: np.ndarray) -> bool:
        """Hold ``ctrl`` (nu,) for ``substeps`` steps from ``state`` (nstate,) float64
        (``mjSTATE_FULLPHYSICS``), writing each substep's sensor values into ``sensordata``
        (substeps, nsensordata).

        Returns True and overwrites ``state`` with the new state if the world stepped normally;
        returns False and leaves ``state`` untouched if MuJoCo raised a warning on the way
        (``sensordata`` is then partly written).
        """
        model, data = self.model, self._data
        mujoco.mj_setState(model, data, state, _FULL)
        self._warmstart[:] = 0.0
        self._ctrl[:] = ctrl
        self._warnings[:] = 0
        for k in range(self.substeps):
            mujoco.mj_step(model, data)
            sensordata[k] = self._sensors
        if np.count_nonzero(self._warnings):
            return False
        mujoco.mj_getState(model, data, state, _FULL)
        return True

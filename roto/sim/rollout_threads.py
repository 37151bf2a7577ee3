"""Step a batch of MuJoCo worlds with ``mujoco.rollout`` on the calling thread plus helper threads.

``rollout``'s own pool (``Rollout(nthread=K)``) leaves the calling thread asleep while K workers
step the batch, and all K workers are woken from sleep at every control step, after the env's
torch work on the calling thread. On the 2-core project machine that made 2-thread physics 8-13 %
slower (benchmarks/README.md). Here the calling thread steps worlds itself and only ``threads - 1``
helpers are woken; every thread takes chunks of worlds from a shared counter until none is left,
so a thread that drew cheap worlds takes more of them.

Each world's result depends only on its own initial state and controls (``rollout`` sets the full
physics state and zeroes the warm start per world), so how worlds fall to threads never changes a
result: 1 and K threads are bit-identical.
"""

from __future__ import annotations

import os
import queue
import threading
import weakref

import mujoco
import numpy as np
from mujoco import rollout

_CTRL = mujoco.mjtState.mjSTATE_CTRL.value


def default_chunk_size(num_worlds: int, threads: int) -> int:
    """Worlds per chunk: all of them on one thread (one ``rollout`` call), else about 8 chunks
    per thread of at most 16 worlds (256 worlds on 2 threads: 16)."""
    if threads == 1:
        return max(1, num_worlds)
    return max(1, min(16, num_worlds // (8 * threads)))


class RolloutThreads:
    """``threads`` threads (the caller and ``threads - 1`` persistent helpers) over one model.

    Helpers hold the pool only weakly: a pool that is dropped without ``close()`` stops its
    helpers when it is garbage-collected. After a ``fork`` the child starts helpers of its own
    (threads do not survive a fork).
    """

    def __init__(self, model: mujoco.MjModel, threads: int, chunk_size: int) -> None:
        if threads < 1:
            raise ValueError(f"threads must be >= 1, got {threads}")
        if chunk_size < 1:
            raise ValueError(f"chunk_size must be >= 1, got {chunk_size}")
        self.model = model
        self.threads = threads
        self.chunk_size = chunk_size
        self._rollouts = [rollout.Rollout(nthread=0) for _ in range(threads)]
        self._datas = [[mujoco.MjData(model)] for _ in range(threads)]
        self._lock = threading.Lock()
        self._job: tuple[np.ndarray, ...] | None = None
        self._nstep = 0
        self._next = 0
        self._closed = False
        self._start_helpers()

    def run(self, state0: np.ndarray, ctrl: np.ndarray, state: np.ndarray, sensordata: np.ndarray, nstep: int) -> None:
        """Roll every world ``nstep`` physics steps; fills the output arrays in place.

        Args:
            state0: (n, nstate) float64 C-contiguous ``mjSTATE_FULLPHYSICS`` start states.
            ctrl: (n, nstep, nu) float64 C-contiguous controls.
            state: (n, nstep, nstate) float64 C-contiguous output states after each step.
            sensordata: (n, nstep, nsensordata) float64 C-contiguous output sensor values.
        """
        if self._closed:
            raise RuntimeError("RolloutThreads was closed")
        if os.getpid() != self._pid:
            self._start_helpers()
        n = len(state0)
        if n == 0:
            return
        self._job = (state0, ctrl, state, sensordata)
        self._nstep = nstep
        self._next = 0
        chunks = -(-n // self.chunk_size)
        woken = min(len(self._todo), chunks - 1)
        for k in range(woken):
            self._todo[k].put(True)
        errors: list[BaseException] = []
        try:
            self._work(0)
        except BaseException as error:  # re-raised below, once the helpers stop
            errors.append(error)
            with self._lock:
                self._next = n  # let the helpers run out of work
        for _ in range(woken):
            error = self._done.get()
            if error is not None:
                errors.append(error)
        self._job = None
        if errors:
            raise errors[0]

    def close(self) -> None:
        """Stop the helper threads (idempotent)."""
        self._stop()
        for helper in self._helpers:
            helper.join()
        self._helpers = []
        self._closed = True

    def _start_helpers(self) -> None:
        """Fresh queues and ``threads - 1`` helper threads for this process."""
        self._pid = os.getpid()
        self._todo: list[queue.SimpleQueue] = [queue.SimpleQueue() for _ in range(self.threads - 1)]
        self._done: queue.SimpleQueue = queue.SimpleQueue()
        self._stop = weakref.finalize(self, _stop_helpers, self._todo)
        self._helpers = [
            threading.Thread(
                target=_helper_loop,
                args=(weakref.ref(self), k + 1, self._todo[k], self._done),
                name=f"roto-rollout-{k + 1}",
                daemon=True,
            )
            for k in range(self.threads - 1)
        ]
        for helper in self._helpers:
            helper.start()

    def _work(self, thread: int) -> None:
        """Take chunks of the current job until none is left, stepping them on ``thread``'s data."""
        state0, ctrl, state, sensordata = self._job
        n = len(state0)
        models = [self.model] * self.chunk_size
        while True:
            with self._lock:
                start = self._next
                self._next += self.chunk_size
            if start >= n:
                return
            end = min(n, start + self.chunk_size)
            self._rollouts[thread].rollout(
                models[: end - start],
                self._datas[thread],
                state0[start:end],
                ctrl[start:end],
                control_spec=_CTRL,
                skip_checks=True,
                nstep=self._nstep,
                state=state[start:end],
                sensordata=sensordata[start:end],
            )


def _stop_helpers(todo: list[queue.SimpleQueue]) -> None:
    """Tell every helper to exit (runs at ``close()`` or when the pool is garbage-collected)."""
    for queue_ in todo:
        queue_.put(False)


def _helper_loop(pool_ref: weakref.ref, thread: int, todo: queue.SimpleQueue, done: queue.SimpleQueue) -> None:
    """Wait for work, step chunks as ``thread``, report; hold the pool only while working."""
    while todo.get():
        pool = pool_ref()
        if pool is None:
            return
        try:
            pool._work(thread)
        except BaseException as error:  # handed to the caller's run()
            done.put(error)
        else:
            done.put(None)
        pool = None  # no strong reference while waiting, so a dropped pool can be collected

"""Step a batch of MuJoCo worlds with ``mujoco.rollout`` on the calling thread plus helper threads.

``rollout``'s own pool (``Rollout(nthread=K)``) leaves the calling thread asleep while K workers
step the batch, and all K workers are woken from sleep at every control step, after the env's
torch work on the calling thread. On the 2-core project machine that made 2-thread physics 8-13 %
slower (benchmarks/README.md). Here the calling thread steps worlds itself and only ``threads - 1``
helpers are woken; every thread takes chunks of worlds from a shared counter until none is left,
so a thread that drew cheap worlds (or runs on a faster core) takes more of them.

Chunks shrink as the batch runs out (a guided schedule): each take is a ``1 / (2·threads)`` share
of the worlds still left, at least ``min_chunk``. Early chunks are large (few ``rollout`` calls),
the last ones are a world or two, so the threads finish within about one world's physics of each
other; with fixed chunks of 16 worlds the first thread done idled for half a chunk on average,
3-6 % of a 2-thread step (benchmarks/README.md).

Each world's result depends only on its own initial state and controls (``rollout`` sets the full
physics state and zeroes the warm start per world), so how worlds fall to threads never changes a
result: 1 and K threads are bit-identical.
"""

from __future__ import annotations

import functools
import itertools
import os
import queue
import threading
import weakref

import mujoco
import numpy as np
from mujoco import rollout

_CTRL = mujoco.mjtState.mjSTATE_CTRL.value


@functools.cache
def chunk_ends(num_worlds: int, threads: int, min_chunk: int = 1) -> tuple[int, ...]:
    """Where each take of ``chunk_sizes`` ends (cumulative sizes; cached, one entry per batch shape)."""
    return tuple(itertools.accumulate(chunk_sizes(num_worlds, threads, min_chunk)))


def chunk_sizes(num_worlds: int, threads: int, min_chunk: int = 1) -> list[int]:
    """The guided schedule: the sizes of successive takes from ``num_worlds`` worlds.

    One thread takes every world in one ``rollout`` call; K threads take ``remaining // (2K)``
    worlds at a time, at least ``min_chunk`` (256 worlds on 2 threads: 64, 48, 36, 27, ..., 1).
    """
    sizes = []
    remaining = num_worlds
    while remaining > 0:
        size = remaining if threads == 1 else min(remaining, max(min_chunk, remaining // (2 * threads)))
        sizes.append(size)
        remaining -= size
    return sizes


class RolloutThreads:
    """``threads`` threads (the caller and ``threads - 1`` persistent helpers) over one model.

    Helpers hold the pool only weakly: a pool that is dropped without ``close()`` stops its
    helpers when it is garbage-collected. After a ``fork`` the child starts helpers of its own
    (threads do not survive a fork).
    """

    def __init__(self, model: mujoco.MjModel, threads: int, min_chunk: int = 1) -> None:
        if threads < 1:
            raise ValueError(f"threads must be >= 1, got {threads}")
        if min_chunk < 1:
            raise ValueError(f"min_chunk must be >= 1, got {min_chunk}")
        self.model = model
        self.threads = threads
        self.min_chunk = min_chunk
        self._rollouts = [rollout.Rollout(nthread=0) for _ in range(threads)]
        self._datas = [[mujoco.MjData(model)] for _ in range(threads)]
        self._lock = threading.Lock()
        self._job: tuple[np.ndarray, ...] | None = None
        self._nstep = 0
        self._chunk_ends: tuple[int, ...] = ()
        self._next = 0
        self._closed = False
        self._start_helpers()

    def run(
        self,
        state0: np.ndarray,
        ctrl: np.ndarray,
        state: np.ndarray,
        sensordata: np.ndarray,
        nstep: int,
        threads: int | None = None,
    ) -> None:
        """Roll every world ``nstep`` physics steps on at most ``threads`` threads (None: all);
        fills the output arrays in place.

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
        threads = self.threads if threads is None else max(1, min(threads, self.threads))
        self._chunk_ends = chunk_ends(n, threads, self.min_chunk)
        self._next = 0
        woken = min(threads - 1, len(self._chunk_ends) - 1)
        for k in range(woken):
            self._todo[k].put(True)
        errors: list[BaseException] = []
        try:
            self.work(0)
        except BaseException as error:  # re-raised below, once the helpers stop
            errors.append(error)
            with self._lock:
                self._next = len(self._chunk_ends)  # let the helpers run out of work
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

    def work(self, thread: int) -> None:
        """Take chunks of the current job until none is left, stepping them on ``thread``'s data."""
        state0, ctrl, state, sensordata = self._job
        ends = self._chunk_ends
        models = [self.model] * ends[0]  # the first chunk is the largest
        while True:
            with self._lock:
                chunk = self._next
                self._next += 1
            if chunk >= len(ends):
                return
            start, end = ends[chunk - 1] if chunk else 0, ends[chunk]
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
            pool.work(thread)
        except BaseException as error:  # handed to the caller's run()
            done.put(error)
        else:
            done.put(None)
        pool = None  # no strong reference while waiting, so a dropped pool can be collected

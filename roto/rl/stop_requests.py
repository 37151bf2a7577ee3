"""Stopping a training run between updates, with a checkpoint of the last one.

While a run trains, the first SIGINT (Ctrl-C, ``timeout --signal=INT``) or SIGTERM (``kill``, a
scheduler's preemption, ``timeout``) only asks it to stop: the update in progress finishes, is
logged and checkpointed, and the run then stops as if interrupted (``KeyboardInterrupt``), so a
resume loses nothing. A second signal stops it at once, from wherever it is (a resume then continues
from the run's previous checkpoint).
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from types import FrameType, TracebackType

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def signal_handlers(handlers: dict[int, Callable[[int, FrameType | None], None]]) -> Iterator[None]:
    """``handlers`` ({signal: handler}) for the block, the previous handlers back after it. Outside
    the main thread, where Python delivers no signals to handlers, it installs nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {signum: signal.signal(signum, handler) for signum, handler in handlers.items()}
    try:
        yield
    finally:
        for signum, handler in previous.items():  # None: a handler not set from Python
            signal.signal(signum, signal.SIG_DFL if handler is None else handler)


class StopRequests:
    """A context that turns the first SIGINT or SIGTERM into a request (``requested``, ``signal_name``)
    and a second into ``KeyboardInterrupt`` (``signal_handlers``: main thread only)."""

    def __init__(self) -> None:
        self.signal_name: str | None = None
        self._handlers = signal_handlers(dict.fromkeys(STOP_SIGNALS, self._handle))

    @property
    def requested(self) -> bool:
        """Whether a stop was asked for since the context was entered."""
        return self.signal_name is not None

    def __enter__(self) -> StopRequests:
        self._handlers.__enter__()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self._handlers.__exit__(kind, error, traceback)

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        name = signal.Signals(signum).name
        if self.requested:
            raise KeyboardInterrupt(f"{name} after {self.signal_name}: stopped at once")
        self.signal_name = name
        print(
            f"roto: {name}: stopping after this update, with a checkpoint (send it again to stop now)",
            file=sys.stderr,
            flush=True,
        )


def interrupt_on_sigterm() -> None:
    """From now on SIGTERM stops this process as Ctrl-C does (``KeyboardInterrupt``), so that ``kill``
    or a scheduler's preemption ends a command through its clean-up (a sweep's or Olympiad's trial
    is failed and re-enqueued at once) instead of killing it. Main thread only; else nothing."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _raise_interrupt)


def _raise_interrupt(signum: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)

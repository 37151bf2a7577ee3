"""One process at a time per run directory: an exclusive lock held while a trainer lives.

The lock is ``fcntl.flock`` on ``<run_dir>/.lock``; the kernel drops it when the process ends, so
a run whose trainer crashed or was killed is free again at once. Where ``fcntl`` is missing (not
POSIX), runs are not locked.
"""

from __future__ import annotations

import os
import pathlib
from typing import IO

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None

LOCK_NAME = ".lock"


def hold_run_lock(run_dir: pathlib.Path) -> IO[str] | None:
    """Lock ``run_dir`` for this process; the open lock file (keep it: closing it unlocks).

    Raises:
        ValueError naming the run and the process that holds it.
    """
    if fcntl is None:
        return None
    handle = (run_dir / LOCK_NAME).open("a+")
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        handle.seek(0)
        holder = handle.read().strip() or "another process"
        handle.close()
        raise ValueError(
            f"run {str(run_dir)!r} is in use by {holder}; wait for it to finish (two processes on one run would "
            "overwrite each other's checkpoints)"
        ) from None
    handle.seek(0)
    handle.truncate()
    handle.write(f"process {os.getpid()}\n")
    handle.flush()
    return handle


def wait_until_free(run_dir: pathlib.Path) -> None:
    """Return once no process holds ``run_dir``'s lock, saying once that it waits.

    For sweep and Olympiad workers about to continue a run whose first worker was declared dead
    (no heartbeat for a while) but may still be alive and training it: that worker releases the run
    when it ends, and the retry then continues from its latest checkpoint instead of failing.
    """
    path = run_dir / LOCK_NAME
    if fcntl is None or not path.is_file():
        return
    with path.open("a+") as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            holder = handle.read().strip() or "another process"
            print(f"roto: run {str(run_dir)!r} is still used by {holder}; waiting until it lets go", flush=True)
            fcntl.flock(handle, fcntl.LOCK_EX)  # closing the file below unlocks it for the trainer

"""Optuna's journal file, made safe against a writer that died in the middle of a line.

Optuna appends one JSON line per operation. A worker killed mid-write leaves half a line at the
end; Optuna's reader tolerates that at the very end, but the next append glues a whole line to the
half, and from then on every reader fails on the corrupt line in the middle. Here every append
first drops such a torn tail, under the journal's own lock (so no writer is mid-line), and says so
on stderr. Only bytes after the last newline are ever removed: no reader has an offset there.
"""

from __future__ import annotations

import json
import os
import pathlib
import sys
from typing import Any

from optuna.storages.journal import JournalFileBackend, JournalFileSymlinkLock

TAIL_CHUNK = 1 << 16


def drop_torn_tail(path: pathlib.Path) -> int:
    """Cut ``path`` back to its last newline; the number of bytes dropped (0 when it ends whole)."""
    with open(path, "r+b") as f:
        size = f.seek(0, os.SEEK_END)
        end = size
        while end > 0:
            start = max(0, end - TAIL_CHUNK)
            f.seek(start)
            newline = f.read(end - start).rfind(b"\n")
            if newline >= 0:
                keep = start + newline + 1
                break
            end = start
        else:
            keep = 0
        if keep < size:
            f.truncate(keep)
        return size - keep


class JournalFile(JournalFileBackend):
    """``JournalFileBackend`` whose appends drop a torn last line first (see the module docstring),
    under Optuna's symlink lock (which works on network filesystems), the one its reads share."""

    def __init__(self, file_path: str) -> None:
        self.path = pathlib.Path(file_path)
        self.lock = JournalFileSymlinkLock(file_path)
        super().__init__(file_path, lock_obj=self.lock)

    def append_logs(self, logs: list[dict[str, Any]]) -> None:
        """Append ``logs`` as JSON lines, flushed to disk, after dropping any torn last line."""
        text = "".join(json.dumps(log, separators=(",", ":")) + "\n" for log in logs)
        self.lock.acquire()
        try:
            dropped = drop_torn_tail(self.path)
            if dropped:
                print(
                    f"roto: warning: {self.path}: dropped a torn last line ({dropped} bytes) that a "
                    "process left when it died while writing; the operation it was writing is lost",
                    file=sys.stderr,
                    flush=True,
                )
            with open(self.path, "ab") as f:
                f.write(text.encode("utf-8"))
                f.flush()
                os.fsync(f.fileno())
        finally:
            self.lock.release()

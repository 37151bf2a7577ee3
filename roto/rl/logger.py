"""Scalar logging to TensorBoard event files and a CSV, both in the run directory."""

from __future__ import annotations

import csv
import pathlib

CSV_NAME = "scalars.csv"


class ScalarLogger:
    """Write every scalar to ``<run_dir>/scalars.csv`` (env_steps, update, tag, value) and TensorBoard.

    The CSV is appended to, so a resumed run continues the same file.
    """

    def __init__(self, run_dir: pathlib.Path, tensorboard: bool = True) -> None:
        self.path = run_dir / CSV_NAME
        new = not self.path.exists()
        self._file = self.path.open("a", newline="")
        self._csv = csv.writer(self._file)
        if new:
            self._csv.writerow(["env_steps", "update", "tag", "value"])
        self._tb = None
        if tensorboard:
            from tensorboardX import SummaryWriter

            self._tb = SummaryWriter(str(run_dir / "tensorboard"))

    def log(self, scalars: dict[str, float], env_steps: int, update: int) -> None:
        """Record ``scalars`` at ``env_steps``."""
        for tag, value in scalars.items():
            self._csv.writerow([env_steps, update, tag, f"{float(value):.9g}"])
            if self._tb is not None:
                self._tb.add_scalar(tag, float(value), env_steps)
        self._file.flush()

    def close(self) -> None:
        """Flush and close both outputs."""
        self._file.close()
        if self._tb is not None:
            self._tb.close()

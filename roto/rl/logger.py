"""Scalar logging to a CSV and TensorBoard event files in the run directory, and optionally to Weights & Biases."""

from __future__ import annotations

import csv
import pathlib
from typing import Any

from roto.result_files import replacing

CSV_NAME = "scalars.csv"


class ScalarLogger:
    """Write every scalar to ``<run_dir>/scalars.csv`` (env_steps, update, tag, value), TensorBoard and W&B.

    The CSV is appended to, so a resumed run continues the same file; rows of updates after
    ``update`` (the checkpoint resumed from, whose updates are run again) are dropped first, and
    TensorBoard hides its events after ``env_steps``, so each update is logged once. ``wandb_run``
    (from ``roto.rl.wandb_run.open_wandb_run``) gets the same scalars at the same env steps and is
    finished on close.
    """

    def __init__(
        self,
        run_dir: pathlib.Path,
        tensorboard: bool = True,
        wandb_run: Any | None = None,
        update: int = 0,
        env_steps: int = 0,
    ) -> None:
        self.path = run_dir / CSV_NAME
        if self.path.exists():
            drop_rows_after(self.path, update)
        new = not self.path.exists()
        self._file = self.path.open("a", newline="")
        self._csv = csv.writer(self._file)
        if new:
            self._csv.writerow(["env_steps", "update", "tag", "value"])
        self._tb = None
        if tensorboard:
            from tensorboardX import SummaryWriter

            # events after the checkpoint's env steps are run again: hidden, not shown twice
            self._tb = SummaryWriter(str(run_dir / "tensorboard"), purge_step=env_steps + 1 if update else None)
        self._wandb = wandb_run

    def log(self, scalars: dict[str, float], env_steps: int, update: int) -> None:
        """Record ``scalars`` at ``env_steps``."""
        for tag, value in scalars.items():
            self._csv.writerow([env_steps, update, tag, f"{float(value):.9g}"])
            if self._tb is not None:
                self._tb.add_scalar(tag, float(value), env_steps)
        self._file.flush()
        if self._wandb is not None:
            self._wandb.log({tag: float(value) for tag, value in scalars.items()}, step=env_steps)

    def close(self) -> None:
        """Flush and close every output."""
        self._file.close()
        if self._tb is not None:
            self._tb.close()
        if self._wandb is not None:
            self._wandb.finish()


def drop_rows_after(path: pathlib.Path, update: int) -> None:
    """Rewrite the CSV at ``path`` (atomically) without the rows of updates after ``update``, and
    without a torn last row."""
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return
    header, body = rows[0], rows[1:]
    kept = [row for row in body if len(row) == len(header) and row[1].isdigit() and int(row[1]) <= update]
    if len(kept) == len(body):
        return
    with replacing(path) as temporary, temporary.open("w", newline="") as f:
        csv.writer(f).writerows([header, *kept])

"""A results folder's manifest: one row per cell summary naming what made it (config, training
aids, the commits that trained and summarised it, task version), written by ``roto results`` beside the tables."""

from __future__ import annotations

import csv
import pathlib

from roto.olympiad.plan import Plan
from roto.olympiad.reference_tables import config_label, training_aids
from roto.result_files import replacing

COLUMNS = (
    "cell",
    "task",
    "task_version",
    "robot",
    "obs",
    "variant",
    "seed",
    "config",
    "training_aids",
    "env_steps",
    "train_wall_s",
    "commit",
    "trained_by",
    "plan",
)


def manifest_rows(summaries: list[dict], plan: Plan | None = None) -> list[dict[str, str]]:
    """One row per summary (``COLUMNS``), cells in name order; a field a summary did not record
    (an older summary's task version) is "not recorded"; a version established after training
    names how (``task_version_check``)."""
    rows = []
    for s in summaries:
        cell = f"{s['task']}-{s['robot']}-{s['obs']}-{s['variant']}-seed{s['seed']}"
        row = {key: str(s.get(key, "not recorded")) for key in COLUMNS}
        row.update(
            cell=cell,
            config=config_label(s, plan),
            training_aids=training_aids(s, plan),
            trained_by=trained_by_label(s),
        )
        if "task_version_check" in s:
            row["task_version"] += f" ({s['task_version_check']})"
        rows.append(row)
    return sorted(rows, key=lambda row: row["cell"])


def trained_by_label(summary: dict) -> str:
    """The commits that trained a cell, each with the env steps it started from ("c1 from 0; c2 from
    8396800"); "not recorded" for a summary without the record (``roto.olympiad.cell.trained_by``)."""
    starts = summary.get("trained_by") or []
    return "; ".join(f"{t['commit']} from {t['from_env_steps']}" for t in starts) or "not recorded"


def write_manifest(summaries: list[dict], path: pathlib.Path, plan: Plan | None = None) -> None:
    """``manifest.csv`` of ``summaries`` at ``path``."""
    with replacing(path) as temporary, temporary.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(manifest_rows(summaries, plan))

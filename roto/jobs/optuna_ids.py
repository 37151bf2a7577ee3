"""The one place roto reads Optuna's private state: a trial's storage id.

Optuna writes a trial's state, heartbeats and system attributes by its storage id, which its
``Trial`` and ``FrozenTrial`` keep as the private ``_trial_id`` (its public ``number`` counts trials
within a study, a different thing). Sweeps and the Olympiad claim, reclaim and retry trials by it.
"""

from __future__ import annotations

from typing import Any


def storage_id(trial: Any) -> int:
    """The storage id of ``trial`` (an ``optuna.Trial`` or ``optuna.trial.FrozenTrial``)."""
    return int(trial._trial_id)  # noqa: SLF001 (Optuna has no public accessor for it)

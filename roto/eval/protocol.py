"""roto's evaluation protocol in numbers (``roto.eval.evaluate.evaluate_policy`` runs it): what
``roto eval``, Olympiad cells and submissions (docs/submissions.md) evaluate with."""

from __future__ import annotations

EVAL_EPISODES = 100
"""Episodes per policy, one per env (so short episodes are not favoured)."""
MAX_PARALLEL_ENVS = 128
"""Envs per evaluation batch."""
EVAL_SEED = 1_000_000
"""Batch b of ``MAX_PARALLEL_ENVS`` episodes resets with seed ``EVAL_SEED + b``; training seeds are
small integers, so evaluation never replays a training run's starts."""

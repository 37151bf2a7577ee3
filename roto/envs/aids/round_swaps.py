"""The round-swaps aid: a swap is paid only after the pair turned ``RoundSwapsSettings.min_turn`` turns
the episode's way round (``roto.tasks.round_swaps``), so a swing out and back earns nothing
(with ``first_paid``, an episode's first swap is paid without that turn). It only sets the task's
``swap_min_turn`` and ``swap_first_paid`` parameters; the task does the rest."""

from __future__ import annotations

from roto.envs.aids.protocol import AidHost, TrainingAid
from roto.envs.aids.settings import RoundSwapsSettings


class RoundSwaps(TrainingAid):
    """Sets the task parameters ``swap_min_turn`` and ``swap_first_paid`` once, when the env is built."""

    def __init__(self, host: AidHost, settings: RoundSwapsSettings) -> None:
        host.task.set_parameter(host.task_state, "swap_min_turn", settings.min_turn)
        host.task.set_parameter(host.task_state, "swap_first_paid", float(settings.first_paid))

"""The round-swaps aid: a swap is paid only after the pair turned ``RoundSwapsSettings.min_turn`` turns
the episode's way round (``roto.tasks.round_swaps``), so a swing out and back earns nothing.
It only sets the task's ``swap_min_turn`` parameter; the task does the rest."""

from __future__ import annotations

from roto.envs.aids.protocol import AidHost, TrainingAid
from roto.envs.aids.settings import RoundSwapsSettings


class RoundSwaps(TrainingAid):
    """Sets the task parameter ``swap_min_turn`` once, when the env is built."""

    def __init__(self, host: AidHost, settings: RoundSwapsSettings) -> None:
        host.task.set_parameter(host.task_state, "swap_min_turn", settings.min_turn)

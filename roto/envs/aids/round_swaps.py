"""The round-swaps aid: a swap is paid only after the pair turned ``RoundSwapsSettings.min_turn`` turns
the episode's way round (``roto.tasks.round_swaps``), so a swing out and back earns nothing
(with ``first_paid``, an episode's first swap is paid without that turn). It only sets the task's
``swap_min_turn`` and ``swap_first_paid`` parameters; the task does the rest.

With ``after``, the aid is armed part way: every swap is paid (``swap_min_turn`` 0) until the
running mean of the training episodes' rotations (``roto.envs.aids.episode_mean``) reaches
``after``, and ``min_turn`` holds from then on. A policy that carries the balls round is paid for
every swap either way; one that learned to swing them out and back stops being paid for it.
"""

from __future__ import annotations

from typing import Any

import torch

from roto.envs.aids.episode_mean import fold_ended_episodes
from roto.envs.aids.protocol import AidHost, StepContext, TrainingAid
from roto.envs.aids.settings import RoundSwapsSettings

ARMED_METRIC = "train/round_swaps_armed"
"""The training scalar of ``ArmedRoundSwaps``: 1 once armed, 0 until then."""


class RoundSwaps(TrainingAid):
    """Sets the task parameters ``swap_min_turn`` and ``swap_first_paid`` once, when the env is built."""

    def __init__(self, host: AidHost, settings: RoundSwapsSettings) -> None:
        host.task.set_parameter(host.task_state, "swap_min_turn", settings.min_turn)
        host.task.set_parameter(host.task_state, "swap_first_paid", float(settings.first_paid))


class ArmedRoundSwaps(TrainingAid):
    """Round swaps armed once the training episodes reach ``settings.after`` rotations: follows every
    ended episode's headline metric, and sets ``swap_min_turn`` to 0 before and ``min_turn`` after,
    on the env's device without reading it."""

    state_key = "round_swaps_armed"
    watches_steps = True

    def __init__(self, host: AidHost, settings: RoundSwapsSettings) -> None:
        self.task, self.task_state = host.task, host.task_state
        self.min_turn, self.after = settings.min_turn, settings.after
        self.mean = torch.zeros((), dtype=torch.float64, device=host.device)
        self.armed = torch.zeros((), dtype=torch.bool, device=host.device)
        host.task.set_parameter(host.task_state, "swap_first_paid", float(settings.first_paid))
        self._apply()

    def _apply(self) -> None:
        min_turn = torch.where(self.armed, self.min_turn, 0.0).to(torch.float64)
        self.task.set_parameter(self.task_state, "swap_min_turn", min_turn)

    def observe(self, step: StepContext) -> None:
        """This step's ended episodes into the running mean; armed for good once it reaches ``after``."""
        self.mean = fold_ended_episodes(self.mean, step.metric, step.done)
        self.armed = self.armed | (self.mean >= self.after)
        self._apply()

    def metrics(self) -> dict[str, torch.Tensor]:
        return {ARMED_METRIC: self.armed.to(torch.float64)}

    def state_dict(self) -> dict[str, Any]:
        return {"mean": self.mean.clone(), "armed": self.armed.clone()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self.mean = state["mean"].clone().to(self.mean.device)
        self.armed = state["armed"].clone().to(self.armed.device)
        self._apply()

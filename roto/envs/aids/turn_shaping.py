"""The turn-shaping aid: a training env earns ``TurnShapingSettings.per_turn`` per turn the pair's net
turning this episode grows, and gives it back as it shrinks (``roto.tasks.round_swaps.turn_shaping``),
so carrying the balls round pays and swinging them out and back does not. It only sets the task's
``turn_reward`` parameter (and with ``lead``, ``near`` or ``soft`` its ``turn_lead``, ``turn_near``
or ``turn_soft``); the task does the rest (a "turn" reward term).

With ``near_from``, ``near`` narrows from ``near_from`` as the training episodes learn to turn the
pair: ``NarrowingTurnShaping`` follows the size of every ended training episode's net turns (the
task state's ``net_turn``) in a ``Narrowing`` and sets ``turn_near`` from it each control step, on
the env's device without reading it."""

from __future__ import annotations

from typing import Any

import torch

from roto.envs.aids.episode_mean import Narrowing
from roto.envs.aids.protocol import AidHost, StepContext, TrainingAid
from roto.envs.aids.settings import TurnShapingSettings


class TurnShaping(TrainingAid):
    """Sets the task parameters ``turn_reward`` (and ``turn_lead``, ``turn_near``, ``turn_soft``) once, when the env
    is built."""

    def __init__(self, host: AidHost, settings: TurnShapingSettings) -> None:
        host.task.set_parameter(host.task_state, "turn_reward", settings.per_turn)
        if settings.lead is not None:  # else the task's own: unbounded
            host.task.set_parameter(host.task_state, "turn_lead", settings.lead)
        if settings.near is not None:  # else the task's own: anywhere
            host.task.set_parameter(host.task_state, "turn_near", settings.near)
        if settings.soft:  # else the task's own: no pay beyond near
            host.task.set_parameter(host.task_state, "turn_soft", 1.0)


class NarrowingTurnShaping(TurnShaping):
    """Turn shaping whose ``near`` narrows from ``settings.near_from`` to ``settings.near`` as the
    training episodes' net turns reach ``settings.near_turns`` (``Narrowing``)."""

    state_key = "turn_near_narrowing"
    watches_steps = True

    def __init__(self, host: AidHost, settings: TurnShapingSettings) -> None:
        super().__init__(host, settings)
        self.task, self.task_state = host.task, host.task_state
        mean = torch.zeros((), dtype=torch.float64, device=host.device)
        self.near = Narrowing(settings.near_from, settings.near, settings.near_turns, mean)
        self.task.set_parameter(self.task_state, "turn_near", self.near.value())

    def observe(self, step: StepContext) -> None:
        """This step's ended episodes' net turns into the running mean, before their task state resets."""
        turns = step.task_state.net_turn.abs()
        self.task.set_parameter(self.task_state, "turn_near", self.near.update(turns, step.done))

    def metrics(self) -> dict[str, torch.Tensor]:
        return {"train/turn_near": self.near.value()}

    def state_dict(self) -> dict[str, Any]:
        return self.near.state_dict()

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self.near.load_state_dict(state)  # turn_near itself comes back with the env's task state

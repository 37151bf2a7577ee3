"""The turn-shaping aid: a training env earns ``TurnShapingSettings.per_turn`` per turn the pair's net
turning this episode grows, and gives it back as it shrinks (``roto.tasks.round_swaps.turn_shaping``),
so carrying the balls round pays and swinging them out and back does not. It only sets the task's
``turn_reward`` parameter (and with ``lead``, ``near`` or ``soft`` its ``turn_lead``, ``turn_near``
or ``turn_soft``); the task does the rest (a "turn" reward term)."""

from __future__ import annotations

from roto.envs.aids.protocol import AidHost, TrainingAid
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

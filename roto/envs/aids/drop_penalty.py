"""The drop-penalty aid: a Bounce training episode that ends with the ball lost is charged
``DropPenaltySettings.per_drop`` on its last control step (the task's "drop" reward term).

Without it a lost ball costs a Bounce agent nothing, and a fresh start drops the ball onto the
palm, where one bounce comes easily: a policy that bounces the ball once and throws it away earns
more per control step early in training than one that keeps it, and some seeds never leave that
(docs/results.md). Charging one bounce's pay per loss takes that profit away; an episode that
keeps the ball for its 10 s is never charged. It only sets the task's ``drop_penalty`` parameter;
the task does the rest."""

from __future__ import annotations

from roto.envs.aids.protocol import AidHost, TrainingAid
from roto.envs.aids.settings import DropPenaltySettings


class DropPenalty(TrainingAid):
    """Sets the task parameter ``drop_penalty`` once, when the env is built."""

    def __init__(self, host: AidHost, settings: DropPenaltySettings) -> None:
        host.task.set_parameter(host.task_state, "drop_penalty", settings.per_drop)

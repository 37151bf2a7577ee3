"""A training-only tolerance curriculum: the task's success radius starts wide and narrows to the
benchmark's as the training episodes succeed.

For a task with a success radius (Baoding's latch radius, the task parameter ``success_radius``):
the radius is ``end + (start - end) * max(0, 1 - mean / target)``, where ``mean`` is the running
mean, over the training episodes that ended so far, of the headline metric (Baoding: rotations)
or, with ``ToleranceSettings.by: net_turns``, of the size of the ball pair's net turning
(``roto.envs.aids.episode_mean.Narrowing``), ``start`` is ``ToleranceSettings.start`` and ``end`` the task's
own radius. So the radius is ``start`` while no episode succeeds, the task's own once the episodes
reach ``ToleranceSettings.target`` on average, and widens again if they fall back; with
``ToleranceSettings.deadline`` it is the task's own from that many training env steps on. The update
runs on the env's device in fixed shapes, never reading it. Evaluation envs never use it
(``EnvConfig.without_training_aids``).
"""

from __future__ import annotations

import torch

from roto.envs.aids.episode_mean import Narrowing
from roto.envs.aids.protocol import AidHost, StepContext, TrainingAid
from roto.envs.aids.settings import ToleranceSettings


class ToleranceAid(TrainingAid):
    """The aid: a ``Narrowing`` of the radius fed the headline metric (or the pair's net turns) of
    every ended training episode, setting the task's ``success_radius`` parameter (the
    ``tolerance`` aid), the task's own radius once ``env_steps`` reaches the deadline."""

    state_key = "tolerance_curriculum"
    watches_steps = True

    def __init__(self, host: AidHost, settings: ToleranceSettings) -> None:
        mean = torch.zeros((), dtype=torch.float64, device=host.device)
        end = host.task.parameters["success_radius"]
        self.curriculum = Narrowing(settings.start, end, settings.target, mean)
        self.task, self.task_state = host.task, host.task_state
        self.by_net_turns = settings.by == "net_turns"
        self.deadline, self.env_steps = settings.deadline, 0
        self.own = torch.tensor(end, dtype=torch.float64, device=host.device)
        self.task.set_parameter(self.task_state, "success_radius", self.radius())

    def radius(self) -> torch.Tensor:
        """() float64, the radius now: the curriculum's, or the task's own past the deadline."""
        past_deadline = self.deadline is not None and self.env_steps >= self.deadline  # host ints: no sync
        return self.own if past_deadline else self.curriculum.value()

    def observe(self, step: StepContext) -> None:
        """This step's ended episodes into the running mean, before their task state resets."""
        measure = step.task_state.net_turn.abs() if self.by_net_turns else step.metric
        self.curriculum.update(measure, step.done)
        self.env_steps += step.done.shape[0]
        self.task.set_parameter(self.task_state, "success_radius", self.radius())

    def metrics(self) -> dict[str, torch.Tensor]:
        return {"train/success_radius": self.radius()}

    def state_dict(self) -> dict[str, object]:
        return {**self.curriculum.state_dict(), "env_steps": self.env_steps}

    def load_state_dict(self, state: dict[str, object]) -> None:
        self.curriculum.load_state_dict(state)
        # a checkpoint saved before the count was kept had no deadline to count towards
        self.env_steps = int(state.get("env_steps", 0))

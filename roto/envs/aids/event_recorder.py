"""States of the training envs' own episodes recorded just before the task's events, for replay.

Reference-state initialisation from the agent's own successes: where the task's headline metric
rises in a world (a Baoding swap, a Bounce bounce), the state that world was in ``lead`` control
steps earlier joins a bank of at most ``capacity`` states (the oldest replaced first), from which
training episodes may start beside the recorded file's states (``ReplayedStartsSettings.record_lead``,
``roto.envs.aids.replayed_starts``). Only states of the same episode count: the event must come more than
``lead`` steps after the episode's start.

Every step the recorder keeps each world's last ``lead`` states in a ring (physics, joint targets,
the task fields the replay bank carries). It works in fixed shapes and never reads the device:
worlds without an event write into a spare row past the bank's end.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch

from roto.envs.aids.protocol import AidHost, StepContext, TrainingAid
from roto.envs.aids.settings import ReplayedStartsSettings
from roto.envs.replay_starts import ReplayBank


@dataclass
class EventRecorder:
    """Ring of the last ``lead`` states per world and the bank of recorded states.

    Attributes:
        lead: control steps between a recorded state and its event.
        ring: name -> (lead, B, ...) the last ``lead`` states of every world; slot ``steps % lead``
            holds the state ``lead`` steps back.
        bank: name -> (capacity + 1, ...) recorded states; the last row is the spare.
        recorded: () int64, states recorded so far (the bank holds ``min(recorded, capacity)``).
        steps: () int64, states pushed into the ring so far.
        last_metric: (B,) the headline metric after the previous step (0 at an episode's start).
    """

    lead: int
    ring: dict[str, torch.Tensor]
    bank: dict[str, torch.Tensor]
    recorded: torch.Tensor
    steps: torch.Tensor
    last_metric: torch.Tensor

    @classmethod
    def empty(cls, lead: int, capacity: int, like: dict[str, torch.Tensor]) -> EventRecorder:
        """A recorder of ``lead`` >= 1 steps and ``capacity`` >= 1 states shaped like the rows
        ``like`` (name -> (B, ...)) that ``observe`` will be given."""
        if lead < 1 or capacity < 1:
            raise ValueError(f"an event recorder needs lead >= 1 and capacity >= 1, got {lead}, {capacity}")
        some = next(iter(like.values()))
        device, num_worlds = some.device, len(some)
        return cls(
            lead=lead,
            ring={name: rows.new_zeros((lead, *rows.shape)) for name, rows in like.items()},
            bank={name: rows.new_zeros((capacity + 1, *rows.shape[1:])) for name, rows in like.items()},
            recorded=torch.zeros((), dtype=torch.int64, device=device),
            steps=torch.zeros((), dtype=torch.int64, device=device),
            last_metric=torch.zeros(num_worlds, dtype=torch.float64, device=device),
        )

    @property
    def capacity(self) -> int:
        return len(next(iter(self.bank.values()))) - 1

    def observe(
        self, rows: dict[str, torch.Tensor], metric: torch.Tensor, length: torch.Tensor, done: torch.Tensor
    ) -> None:
        """One control step of every world: record the state ``lead`` steps back where ``metric``
        (B,) rose in an episode now ``length`` (B,) > ``lead`` steps long, then push this step's
        ``rows`` (name -> (B, ...)); ``done`` (B,) marks episodes that end now (their metric
        restarts at 0)."""
        metric = metric.to(torch.float64)
        event = (metric > self.last_metric) & (length > self.lead)
        slot = (self.steps % self.lead).view(1)  # (1,) on the device: indexing by a 0-d tensor reads it back
        capacity = self.capacity
        position = (self.recorded + torch.cumsum(event.to(torch.int64), 0) - 1) % capacity
        position = torch.where(event, position, capacity)  # the spare row takes the worlds without one
        for name, ring in self.ring.items():
            self.bank[name][position] = ring.index_select(0, slot)[0]
            ring.index_copy_(0, slot, rows[name].to(ring.dtype).unsqueeze(0))
        self.recorded += event.sum()
        self.steps += 1
        self.last_metric = metric.masked_fill(done, 0.0)

    def held(self) -> torch.Tensor:
        """() int64, states in the bank now."""
        return torch.clamp(self.recorded, max=self.capacity)

    def as_bank(self, fields: tuple[str, ...]) -> tuple[ReplayBank, torch.Tensor]:
        """The whole bank (spare row dropped; rows past ``held()`` are zeros) as a ``ReplayBank``
        whose task fields are ``fields``, and how many of its rows hold states."""
        rows = {name: values[:-1] for name, values in self.bank.items()}
        bank = ReplayBank(rows["qpos"], rows["qvel"], rows["target"], {name: rows[f"task/{name}"] for name in fields})
        return bank, self.held()

    def state_dict(self) -> dict[str, object]:
        """Copies of everything (saved with the env, so a resume records and draws as before)."""
        return {
            "lead": self.lead,
            "ring": {name: value.clone() for name, value in self.ring.items()},
            "bank": {name: value.clone() for name, value in self.bank.items()},
            "recorded": self.recorded.clone(),
            "steps": self.steps.clone(),
            "last_metric": self.last_metric.clone(),
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, object], device: torch.device) -> EventRecorder:
        """Inverse of ``state_dict``."""
        return cls(
            lead=int(state["lead"]),
            ring={name: value.clone().to(device) for name, value in state["ring"].items()},
            bank={name: value.clone().to(device) for name, value in state["bank"].items()},
            recorded=state["recorded"].clone().to(device),
            steps=state["steps"].clone().to(device),
            last_metric=state["last_metric"].clone().to(device),
        )


class RecordedEvents(TrainingAid):
    """The aid: records the training envs' own states ``lead`` steps before each rise of the task's
    headline metric (``ReplayedStartsSettings.record_lead``); ``ReplayedStarts`` draws from them beside
    its file's states."""

    state_key = "event_recorder"
    watches_steps = True

    def __init__(self, host: AidHost, settings: ReplayedStartsSettings, task_fields: tuple[str, ...]) -> None:
        b = host.config.num_envs
        sizes = {"qpos": host.model.nq, "qvel": host.model.nv, "target": host.robot.num_actions}
        like = {name: torch.zeros(b, size, dtype=torch.float64, device=host.device) for name, size in sizes.items()}
        like.update({f"task/{name}": getattr(host.task_state, name) for name in task_fields})
        self.task_fields = task_fields
        self.recorder = EventRecorder.empty(settings.record_lead, settings.record_capacity, like)
        self.device = host.device

    def observe(self, step: StepContext) -> None:
        """Push this step's state; record the state ``lead`` steps back where the metric rose."""
        rows = {"qpos": step.qpos, "qvel": step.qvel, "target": step.target}
        rows.update({f"task/{name}": getattr(step.task_state, name) for name in self.task_fields})
        self.recorder.observe(rows, step.metric, step.length, step.done)

    def on_reset(self) -> None:
        """Every episode starts over: no metric to rise from."""
        self.recorder.last_metric.zero_()

    def state_dict(self) -> dict[str, object]:
        return self.recorder.state_dict()

    def load_state_dict(self, state: dict[str, object]) -> None:
        self.recorder = EventRecorder.from_state_dict(state, self.device)


def with_recorded(bank: ReplayBank, recorder: EventRecorder, n: int, generator: torch.Generator):
    """``bank`` with the recorder's states appended, and n indices drawn uniformly from the states it
    holds (the file's and those recorded so far), on the device, without reading it."""
    own, held = recorder.as_bank(tuple(bank.task))
    both = ReplayBank(
        torch.cat([bank.qpos, own.qpos]),
        torch.cat([bank.qvel, own.qvel]),
        torch.cat([bank.target, own.target]),
        {name: torch.cat([values, own.task[name].to(values.dtype)]) for name, values in bank.task.items()},
    )
    total = len(bank) + held
    uniform = torch.rand(n, generator=generator, device=bank.qpos.device, dtype=torch.float64)
    return both, torch.clamp((uniform * total).to(torch.int64), max=len(both) - 1)

"""The replayed-starts aid: a share of the training episodes starts from recorded states.

Each start is, with probability ``ReplayedStartsSettings.share``, a state drawn uniformly from the bank
of recorded states (``roto.envs.replay_starts``; with ``RecordedEvents``, also from the states the
envs recorded themselves), with the task state it was recorded in, kept as recorded; otherwise the
draw it wraps (the task's own starts).
"""

from __future__ import annotations

import torch

from roto.envs.aids.event_recorder import RecordedEvents, with_recorded
from roto.envs.aids.protocol import AidHost, DrawStarts, StartRows, TrainingAid
from roto.envs.aids.settings import ReplayedStartsSettings
from roto.envs.replay_starts import ReplayBank, load_replay_bank


class ReplayedStarts(TrainingAid):
    """Draws ``share`` of the starts from the settings' bank, plus the
    states ``recorded`` holds when the envs record their own."""

    state_key = "replay_bank"

    def __init__(self, host: AidHost, settings: ReplayedStartsSettings) -> None:
        robot, task = host.robot, host.task
        bank = load_replay_bank(settings.bank, host.model, robot.name, task.name, host.task_state, robot.num_actions)
        self.bank, self.share, self.device = bank.to(host.device), settings.share, host.device
        self.first_frame = host.first_frame
        self.recorded: RecordedEvents | None = None
        """The envs' own recorded states, drawn alike beside the bank's (``record_own_events``)."""

    def record_own_events(self, host: AidHost, settings: ReplayedStartsSettings) -> RecordedEvents:
        """The aid that records the envs' own states before each event, with this bank's task
        fields; its states are drawn from beside the bank's from now on."""
        self.recorded = RecordedEvents(host, settings, tuple(self.bank.task))
        return self.recorded

    def start_task_fields(self) -> tuple[str, ...]:
        """The task state fields the bank's states were recorded in (none while nothing replays)."""
        return tuple(self.bank.task) if self.share > 0.0 else ()

    def draw_starts(self, n: int, draw: DrawStarts, generator: torch.Generator) -> StartRows:
        """n starts: each replayed with probability ``share``, else one of ``draw``'s. Rows as
        ``draw``'s plus "replayed" (n,) bool and the recorded task fields ("task/<field>", zero
        where fresh)."""
        if self.share == 0.0:
            return draw(n)
        replayed = torch.rand(n, generator=generator, device=self.device) < self.share
        parts = []
        if bool(replayed.any()):
            parts.append((replayed, self.replayed(int(replayed.sum()), generator)))
        if not bool(replayed.all()):
            own = draw(int((~replayed).sum()))
            k = len(own["qpos"])
            own.update({f"task/{name}": rows.new_zeros((k, *rows.shape[1:])) for name, rows in self.bank.task.items()})
            parts.append((~replayed, own))
        starts = {name: rows.new_zeros((n, *rows.shape[1:])) for name, rows in parts[0][1].items()}
        for mask, rows in parts:
            for name, value in rows.items():
                starts[name][mask] = value
        starts["replayed"] = replayed
        return starts

    def replayed(self, n: int, generator: torch.Generator) -> StartRows:
        """n starts drawn uniformly from the bank (and the recorded states): their qpos, qvel,
        joint targets, recorded task state ("task/<field>") and first frame."""
        bank = self.bank
        if self.recorded is None:
            pick = torch.randint(len(bank), (n,), generator=generator, device=self.device)
        else:  # the file's states and the env's own recorded ones, drawn alike
            bank, pick = with_recorded(bank, self.recorded.recorder, n, generator)
        qpos, qvel, target = bank.qpos[pick], bank.qvel[pick], bank.target[pick]
        task_rows = {name: values[pick] for name, values in bank.task.items()}
        recorded = {f"task/{name}": rows for name, rows in task_rows.items()}
        return {
            "qpos": qpos,
            "qvel": qvel,
            "target": target,
            **recorded,
            **self.first_frame(qpos, qvel, target, task_rows),
        }

    def state_dict(self) -> dict[str, object]:
        return self.bank.state_dict()

    def load_state_dict(self, state: dict[str, object]) -> None:
        """The states the run drew from, whatever the file holds now."""
        self.bank = ReplayBank.from_state_dict(state, self.device)

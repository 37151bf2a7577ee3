"""An env's training aids, looped over as one (as PPO loops over its auxiliary losses)."""

from __future__ import annotations

import functools
from collections.abc import Iterator
from typing import Any, TypeVar

import torch

from roto.envs.aids.protocol import DrawStarts, StepContext, TrainingAid

AidT = TypeVar("AidT", bound=TrainingAid)


class AidSet:
    """The aids an env's config switched on (``roto.envs.aids.build``), in the section's order; an
    evaluation env's set is empty.

    Attributes:
        start_task_fields: task state fields the aids' starts carry ("task/<field>" rows).
        watching: the aids shown every step (``TrainingAid.watches_steps``).
    """

    def __init__(self, aids: tuple[TrainingAid, ...]) -> None:
        self._aids = aids
        self.start_task_fields = tuple(name for aid in aids for name in aid.start_task_fields())
        self.watching = tuple(aid for aid in aids if aid.watches_steps)

    def __iter__(self) -> Iterator[TrainingAid]:
        return iter(self._aids)

    def __len__(self) -> int:
        return len(self._aids)

    def find(self, kind: type[AidT]) -> AidT | None:
        """The aid of type ``kind``, or None."""
        return next((aid for aid in self._aids if isinstance(aid, kind)), None)

    def draw_through(self, draw: DrawStarts, generator: torch.Generator) -> DrawStarts:
        """``draw`` (the task's own starts) wrapped by each aid in turn: an aid may start some
        episodes elsewhere."""
        for aid in self._aids:
            draw = functools.partial(aid.draw_starts, draw=draw, generator=generator)
        return draw

    def observe(self, step: StepContext) -> None:
        """Show one control step to every watching aid."""
        for aid in self.watching:
            aid.observe(step)

    def on_reset(self) -> None:
        """Every world starts a new episode."""
        for aid in self._aids:
            aid.on_reset()

    def metrics(self) -> dict[str, torch.Tensor]:
        """Every aid's scalars ("train/<name>" -> () tensor on the env's device)."""
        return {name: value for aid in self._aids for name, value in aid.metrics().items()}

    def state_dict(self) -> dict[str, Any]:
        """{aid's ``state_key``: its state} of the aids with state."""
        return {aid.state_key: aid.state_dict() for aid in self._aids if aid.state_key}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore each aid's state from ``state`` (an env state holding ``state_dict``'s entries).

        Raises:
            ValueError naming the aids whose state is missing (a state saved without them).
        """
        missing = [aid.state_key for aid in self._aids if aid.state_key and aid.state_key not in state]
        if missing:
            raise ValueError(f"the env state holds no state of the training aids {missing}: saved without them")
        for aid in self._aids:
            if aid.state_key:
                aid.load_state_dict(state[aid.state_key])

"""Where an env's episodes start: the task's own starts (``roto.envs.start_draw``), drawn through
the training aids (which may start some elsewhere), from the env's seeded generator, pooled ahead
(``roto.envs.start_pool.StartPool``) so a reset only copies rows."""

from __future__ import annotations

import functools
from typing import Any

import torch

from roto.envs.aids.aid_set import AidSet
from roto.envs.start_draw import StartSource, draw_candidates, draw_starts, first_frame
from roto.envs.start_pool import StartPool, Starts


class EpisodeStarts:
    """The episode starts of one env.

    Attributes:
        generator: the reset noise's generator (seeded by the env's config; ``reseed``).
        pool: the starts drawn ahead, handed out in order.
    """

    def __init__(self, env: StartSource, seed: int) -> None:
        """``env``: the public parts drawing a start reads (``StartSource``); ``seed``: the reset noise's."""
        self.env = env
        self.generator = torch.Generator(device=env.device)
        self.generator.manual_seed(seed)
        self.aids = AidSet(())
        self.pool = StartPool(self.draw, size=env.config.num_envs, device=env.device)

    def draw_through(self, aids: AidSet) -> None:
        """Draw every later start through ``aids`` (built after this, as they draw first frames here)."""
        self.aids = aids

    def draw(self, n: int) -> Starts:
        """n episode starts: the task's own (``start_draw.draw_starts``), drawn through each aid in turn."""
        own = functools.partial(draw_starts, self.env, generator=self.generator)
        return self.aids.draw_through(own, self.generator)(n)

    def first_frame(
        self, qpos: torch.Tensor, qvel: torch.Tensor, target: torch.Tensor, task_rows: dict[str, torch.Tensor]
    ) -> dict[str, torch.Tensor]:
        """The first frame ("frame/<group>" rows) of starts an aid draws (``start_draw.first_frame``)."""
        return first_frame(self.env, qpos, qvel, target, task_rows)[0]

    def candidates(self, n: int, generator: torch.Generator | None = None) -> Starts:
        """n candidates of the task's own starts (``start_draw.draw_candidates``), from ``generator``
        (default: the env's)."""
        return draw_candidates(self.env, n, generator or self.generator)

    def reseed(self, seed: int) -> None:
        self.generator.manual_seed(int(seed))

    def state_dict(self) -> dict[str, Any]:
        return {"generator": self.generator.get_state(), "starts": self.pool.state_dict()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self.generator.set_state(state["generator"].cpu())
        self.pool.load_state_dict(state["starts"], self.env.device)

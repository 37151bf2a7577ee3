"""When an env's step may read the device, and what it checks then.

Reading the device is free on the CPU and waits for a GPU. A sync-free step (a GPU env's) reads
nothing: resets run masked every step, and the pool of starts and the action check are read every
``every`` steps, the pool holding enough starts for every world to reset on each of them. Tests
switch it on for a CPU env (``go_sync_free``) to check it against the CPU path.
"""

from __future__ import annotations

from typing import Any

import torch

from roto.envs.action_checks import check_action_finite, check_action_layout

DEVICE_CHECK_EVERY = 16
"""Steps between the host reads of a GPU env (pool of starts, action finiteness)."""


class StepChecks:
    """Attributes: ``sync_free`` (the step never reads the device), ``every`` (steps between the
    periodic checks; 1 where reading is free), ``since`` (steps since the last check)."""

    def __init__(self, device: torch.device) -> None:
        self.sync_free = device.type != "cpu"
        self.every = DEVICE_CHECK_EVERY if self.sync_free else 1
        self.since = 0
        self.actions_finite = torch.ones((), dtype=torch.bool, device=device)

    def go_sync_free(self, every: int) -> None:
        """Step as a GPU env does, checking every ``every`` steps (for tests on the CPU)."""
        self.sync_free, self.every = True, every

    def action(self, action: Any, shape: tuple[int, int], device: torch.device) -> torch.Tensor:
        """``action`` as a (B, n_act) tensor on ``device``; a non-finite one is refused now, or in
        a sync-free step at the next periodic check."""
        action = check_action_layout(action, shape, device)
        if self.sync_free:
            self.actions_finite &= torch.isfinite(action).all()
        else:
            check_action_finite(action)
        return action

    def step_done(self) -> bool:
        """Count a step; whether the periodic check is due now (then counting starts over)."""
        self.since += 1
        due = self.since == self.every
        if due:
            self.since = 0
        return due

    def raise_on_nonfinite_actions(self) -> None:
        """Raise ValueError if an action since the last check was not finite (reads the device)."""
        if not bool(self.actions_finite):
            self.actions_finite.fill_(True)
            raise ValueError(
                f"an action had non-finite values (NaN or inf) in the last {self.every} steps; "
                "actions must be finite (on a GPU they are checked every few steps, not before each one)"
            )

"""Predictive sampling: model-predictive control by sampling open-loop plans over the true dynamics.

Each control step, ``samples`` plans are rolled out from copies of the current physics state with
``mujoco.rollout``: the nominal plan (the previous best, shifted one step in time) and noisy
copies of it. A plan is a piecewise-linear spline of ``knots`` joint-target vectors over
``horizon`` control steps, held for ``substeps`` physics steps each, as the env holds its targets.
The cheapest rollout becomes the new nominal and its first targets are applied. This is the
predictive-sampling planner of MuJoCo MPC (Howell et al., 2022), written over ``mujoco.rollout``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout

_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS.value
_CTRL = mujoco.mjtState.mjSTATE_CTRL.value

Cost = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""cost(states (N, H, nstate) at the end of each control step, targets (N, H, nu)) -> (N,)."""


@dataclass(frozen=True, kw_only=True)
class SamplingConfig:
    """Predictive-sampling settings.

    Attributes:
        samples: plans rolled out per control step, the nominal one included.
        horizon: control steps per plan.
        knots: spline knots per plan, spread evenly over the horizon.
        sigma: standard deviation of the knots' noise, as a fraction of each joint's half range.
        substeps: physics steps per control step.
        threads: threads ``mujoco.rollout`` steps the samples on.
        seed: seed of the sampling noise.
    """

    samples: int = 32
    horizon: int = 30
    knots: int = 4
    sigma: float = 0.3
    substeps: int = 4
    threads: int = 2
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("samples", "horizon", "knots", "substeps", "threads"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
        if self.knots < 2 or self.knots > self.horizon:
            raise ValueError(f"knots must be in [2, horizon={self.horizon}], got {self.knots}")
        if not self.sigma > 0.0:
            raise ValueError(f"sigma must be > 0, got {self.sigma!r}")


def spline(knots: np.ndarray, horizon: int) -> np.ndarray:
    """Piecewise-linear interpolation of knots spread evenly over ``horizon`` steps.

    Args:
        knots: (N, K, nu) knot values at steps 0, (H-1)/(K-1), ..., H-1.
        horizon: H.

    Returns:
        (N, H, nu) values at steps 0 .. H-1.
    """
    k = knots.shape[1]
    position = np.linspace(0.0, k - 1.0, horizon)  # knot coordinate of each step
    left = np.minimum(position.astype(np.int64), k - 2)
    weight = (position - left)[None, :, None]
    return (1.0 - weight) * knots[:, left] + weight * knots[:, left + 1]


def shifted_knots(knots: np.ndarray, horizon: int, shift: int = 1) -> np.ndarray:
    """The knots of ``knots``' spline advanced ``shift`` steps in time, the last value held.

    Args:
        knots: (K, nu).

    Returns:
        (K, nu): the spline's values at steps shift, shift + (H-1)/(K-1), ... (clamped to H-1).
    """
    k = len(knots)
    times = np.linspace(0.0, horizon - 1.0, k) + shift
    position = np.clip(times / (horizon - 1.0) * (k - 1.0), 0.0, k - 1.0)
    left = np.minimum(position.astype(np.int64), k - 2)
    weight = (position - left)[:, None]
    return (1.0 - weight) * knots[left] + weight * knots[left + 1]


class PredictiveSampling:
    """Plans joint targets for one world of ``model`` (actuated joints within [lo, hi])."""

    def __init__(self, model: mujoco.MjModel, lo: np.ndarray, hi: np.ndarray, config: SamplingConfig) -> None:
        self.model = model
        self.config = config
        self.lo, self.hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        self._rng = np.random.default_rng(config.seed)
        self._datas = [mujoco.MjData(model) for _ in range(config.threads)]
        self._runner = rollout.Rollout(nthread=config.threads)
        self._nominal: np.ndarray | None = None  # (K, nu) knots of the current best plan
        self.last_cost = np.nan

    def reset(self, target: np.ndarray) -> None:
        """Start planning from a plan that holds ``target`` (nu,)."""
        self._nominal = np.repeat(np.asarray(target, dtype=np.float64)[None], self.config.knots, axis=0)

    def close(self) -> None:
        """Release the rollout threads."""
        self._runner.close()

    def plan(self, state: np.ndarray, cost: Cost) -> np.ndarray:
        """Roll out the samples from ``state`` (nstate,) ``mjSTATE_FULLPHYSICS``; return the targets
        (nu,) of the cheapest plan's first control step, which becomes the next nominal plan."""
        if self._nominal is None:
            raise RuntimeError("call reset(target) before plan()")
        c = self.config
        half = 0.5 * (self.hi - self.lo)
        noise = self._rng.standard_normal((c.samples, c.knots, len(self.lo))) * (c.sigma * half)
        noise[0] = 0.0  # the nominal plan competes too
        knots = np.clip(self._nominal[None] + noise, self.lo, self.hi)
        targets = spline(knots, c.horizon)  # (N, H, nu)
        control = np.ascontiguousarray(np.repeat(targets, c.substeps, axis=1))
        states, _ = self._runner.rollout(
            self.model,
            self._datas,
            np.ascontiguousarray(np.broadcast_to(state, (c.samples, len(state)))),
            control,
            control_spec=_CTRL,
        )
        costs = cost(states[:, c.substeps - 1 :: c.substeps], targets)
        best = int(np.argmin(costs))
        self.last_cost = float(costs[best])
        self._nominal = shifted_knots(knots[best], c.horizon)
        return targets[best, 0].copy()

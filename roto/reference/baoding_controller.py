"""The Baoding reference controller: predictive sampling over the true dynamics, run in a roto env.

It reads the simulator's full state (it is a reference, not an agent) and plays the benchmark's
own task: a one-world ``RotoEnv`` counts the swaps, so its figures are the benchmark's metric. On
the way it records the states a few control steps before each swap, from which training episodes
can start (``save_preswap_states``).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import sys
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import torch

from roto.artifact_formats import FORMATS
from roto.envs.ball_paths import BALL_GROUP, BallPathRecorder
from roto.envs.control import target_to_action
from roto.envs.roto_env import RotoEnv
from roto.reference.baoding_cost import BaodingCostWeights, baoding_rollout_cost
from roto.reference.predictive_sampling import PredictiveSampling, SamplingConfig
from roto.registry import make
from roto.sim.mujoco_cpu import state_offsets
from roto.tasks.baoding import SUCCESS_RADIUS

PRESWAP_LEAD = 10
"""Control steps before a swap at which its pre-swap state is recorded (1/6 s)."""


@dataclass
class PreswapStates:
    """States recorded a few control steps before swaps (``PRESWAP_LEAD`` by default), one row each."""

    physics: list[np.ndarray] = field(default_factory=list)  # (nstate,) mjSTATE_FULLPHYSICS
    target: list[np.ndarray] = field(default_factory=list)  # (nu,) joint targets held then
    swapped: list[bool] = field(default_factory=list)  # target assignment then
    latched: list[np.ndarray] = field(default_factory=list)  # (2,) latches then
    lead: list[int] = field(default_factory=list)  # control steps before the swap

    def record(self, history: Sequence[tuple[np.ndarray, np.ndarray, bool, np.ndarray]], leads: Sequence[int]) -> None:
        """At a swap: add the state ``lead`` steps before it for each of ``leads`` that ``history``
        (the states before the swap's step, oldest first; ``history[-1]`` is 1 step before) reaches."""
        for lead in leads:
            if lead <= len(history):
                physics, target, was_swapped, was_latched = history[-lead]
                self.physics.append(physics)
                self.target.append(target)
                self.swapped.append(was_swapped)
                self.latched.append(was_latched)
                self.lead.append(lead)


class BaodingReference:
    """Predictive sampling over ``env``'s true dynamics (one world, CPU backend) towards its next swap."""

    def __init__(self, env: RotoEnv, planner: PredictiveSampling, weights: BaodingCostWeights) -> None:
        if env.num_envs != 1 or env.config.backend != "cpu":
            raise ValueError("the reference controller runs a one-world env on the cpu backend")
        self.env, self.planner, self.weights = env, planner, weights
        qpos0 = state_offsets(env.model)[0]
        self._ball_index = (qpos0 + env.layout.ball_qpos)[:, None] + np.arange(3)[None]  # (2, 3) state columns
        self._targets = env.task_state.targets.cpu().numpy()

    def start(self) -> None:
        """Plan afresh from the env's current state, first holding its current joint targets."""
        self.planner.reset(self.env.joint_targets[0].numpy())

    def act(self) -> torch.Tensor:
        """The (1, n) action of the cheapest plan from the env's current physics and task state."""
        env = self.env
        cost = functools.partial(
            _cost,
            ball_index=self._ball_index,
            targets=self._targets,
            swapped=bool(env.task_state.swapped[0]),
            latched=env.task_state.latched[0].numpy().copy(),
            weights=self.weights,
        )
        joint_target = self.planner.plan(env.backend.physics_state()[0], cost)
        return target_to_action(torch.from_numpy(joint_target)[None], env.indices.ctrl_lo, env.indices.ctrl_hi)


def run_reference_episode(
    controller: BaodingReference, preswap: PreswapStates | None = None, leads: Sequence[int] = (PRESWAP_LEAD,)
) -> dict[str, float]:
    """One episode of the controller's env (reset here); records into ``preswap`` the states
    ``leads`` control steps before each swap.

    Returns the episode's swaps, rotations, return, length, seconds of wall time, and the task's
    path metrics (the pair's net and travelled turns: whether the balls went round each other).
    """
    env = controller.env
    obs, _ = env.reset()
    act = BallPathRecorder(lambda _: controller.act(), len(env.balls))  # keeps the balls' path as it acts
    controller.start()
    history: deque[tuple[np.ndarray, np.ndarray, bool, np.ndarray]] = deque(maxlen=max(leads))
    start = time.perf_counter()
    while True:
        history.append(
            (
                env.backend.physics_state()[0],
                env.joint_targets[0].numpy().copy(),
                bool(env.task_state.swapped[0]),
                env.task_state.latched[0].numpy().copy(),
            )
        )
        obs, _, terminated, truncated, info = env.step(act(obs))
        if preswap is not None and float(info["reward_terms"]["swap"][0]) > 0:
            preswap.record(history, leads)
        if bool(terminated[0] | truncated[0]):
            episode = info["episode"]
            ends = {name: episode[name] for name in env.task.metric_names}
            paths = act.path_metrics(env.task, episode["l"], ends)  # the episode's own observations
            return {
                "swaps": float(episode["swaps"][0]),
                "rotations": float(episode["rotations"][0]),
                "return": float(episode["r"][0]),
                "length": int(episode["l"][0]),
                "seconds": time.perf_counter() - start,
                **{name: values[0] for name, values in paths.items()},
            }


def _cost(
    states: np.ndarray,
    joint_targets: np.ndarray,
    *,
    ball_index: np.ndarray,
    targets: np.ndarray,
    swapped: bool,
    latched: np.ndarray,
    weights: BaodingCostWeights,
) -> np.ndarray:
    return baoding_rollout_cost(
        states[:, :, ball_index], targets, swapped, latched, joint_targets, SUCCESS_RADIUS, weights
    )


def reference_env(robot: str, seed: int, episode_steps: int = 600, **options: object) -> RotoEnv:
    """The one-world Baoding env the reference controller plays (benchmark settings, unless
    ``options`` change them: e.g. ``replay_starts`` to start from recorded states), also returning
    the balls' state for the path metrics."""
    config = {"obs_mode": "blind", "episode_steps": episode_steps, "extra_groups": (BALL_GROUP,), **options}
    return make("baoding", robot=robot, num_envs=1, seed=seed, **config)


def save_preswap_states(path, robot: str, states: PreswapStates) -> None:
    """Write the pre-swap states to an ``.npz`` (arrays named as ``PreswapStates``' fields, the
    leads as ``lead_steps``), the format an env's ``replay_starts`` reads (``roto.envs.replay_starts``)."""
    np.savez_compressed(
        path,
        robot=np.array(robot),
        task=np.array("baoding"),
        format=np.array(FORMATS["bank"]),
        lead_steps=np.array(states.lead, dtype=np.int64),
        physics=np.array(states.physics).reshape(len(states.physics), -1),
        target=np.array(states.target).reshape(len(states.target), -1),
        swapped=np.array(states.swapped, dtype=bool),
        latched=np.array(states.latched, dtype=bool).reshape(-1, 2),
    )


def run_reference_baoding(
    robot: str = "shadow",
    episodes: int = 16,
    seed: int = 0,
    threads: int = 2,
    preswap_path=None,
    preswap_leads: Sequence[int] = (PRESWAP_LEAD,),
    progress: bool = False,
    sampling: SamplingConfig | None = None,
    weights: BaodingCostWeights | None = None,
) -> dict[str, object]:
    """``episodes`` full Baoding episodes of ``robot`` under the reference controller, one after the
    other from the env's own starts (seeded by ``seed``); their swaps and rotations per episode.

    Writes the states ``preswap_leads`` control steps before each swap to ``preswap_path``
    (``.npz``) when given.
    """
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {episodes!r}")
    if not preswap_leads or any(isinstance(k, bool) or not isinstance(k, int) or k < 1 for k in preswap_leads):
        raise ValueError(f"preswap_leads must be control steps, integers >= 1, got {list(preswap_leads)!r}")
    sampling = sampling or SamplingConfig(seed=seed, threads=threads)
    weights = weights or BaodingCostWeights()
    env = reference_env(robot, seed)
    planner = PredictiveSampling(env.model, env.indices.ctrl_lo.numpy(), env.indices.ctrl_hi.numpy(), sampling)
    controller = BaodingReference(env, planner, weights)
    preswap = PreswapStates()
    per_episode = []
    try:
        for k in range(episodes):
            result = run_reference_episode(controller, preswap, preswap_leads)
            per_episode.append(result)
            if progress:
                print(f"episode {k + 1}/{episodes}: {json.dumps(result)}", file=sys.stderr, flush=True)
    finally:
        planner.close()
        env.close()
    if preswap_path is not None:
        save_preswap_states(preswap_path, env.robot.name, preswap)
    rotations = np.array([r["rotations"] for r in per_episode])
    return {
        "task": "baoding",
        "robot": env.robot.name,
        "controller": "predictive sampling (roto.reference)",
        "sampling": dataclasses.asdict(sampling),
        "weights": dataclasses.asdict(weights),
        "episodes": episodes,
        "mean_rotations": float(rotations.mean()),
        "std_rotations": float(rotations.std()),
        "min_rotations": float(rotations.min()),
        "max_rotations": float(rotations.max()),
        "mean_swaps": float(2.0 * rotations.mean()),
        **{f"mean_{name}": float(np.mean([r[name] for r in per_episode])) for name in env.task.path_metric_names},
        "mean_length": float(np.mean([r["length"] for r in per_episode])),
        "seconds_per_episode": float(np.mean([r["seconds"] for r in per_episode])),
        "preswap_states": len(preswap.physics),
        "preswap_leads": list(preswap_leads),
        "per_episode": per_episode,
    }

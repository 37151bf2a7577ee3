"""A task is written once for every hand: a toy task, defined here and registered as
docs/developer.md's "Adding a task" says, makes envs on all four hands, steps, ends and reports
episodes, and trains one PPO update, with no file of roto's changed."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import pytest
import torch

import roto
from roto.robots import ROBOTS
from roto.robots.spec import RobotSpec
from roto.sim.scene import BallSpec
from roto.tasks.base import PALM_DROP_LIMIT, StepResult, TaskInputs, clear_where, set_state_parameter, uniform


@dataclass
class HoldState:
    held: torch.Tensor  # (B,) float32: control steps so far with the ball in contact with the hand


class Hold:
    """Keep a ball on the hand: +1 a step while the hand touches it; the episode ends if it drops."""

    name, display_name, version = "hold", "Hold", 0
    metric_names = ("held",)
    headline_metric = "held"
    selection_metric = None
    reference_name = "no reference"
    reference: Mapping[str, float] = MappingProxyType({})
    observation_size = 1
    path_metric_names = ()
    parameters: Mapping[str, float] = MappingProxyType({})

    def balls(self, robot: RobotSpec) -> tuple[BallSpec, ...]:
        return (BallSpec(name="ball", radius=0.03, mass=0.03),)

    def init_state(self, robot: RobotSpec, num_envs: int, device: torch.device) -> HoldState:
        return HoldState(torch.zeros(num_envs, dtype=torch.float32, device=device))

    def reset(self, state: HoldState, mask: torch.Tensor) -> None:
        clear_where(state.held, mask)

    def initial_ball_positions(self, state: HoldState, n: int, generator: torch.Generator) -> torch.Tensor:
        pos = uniform(generator, (n, 1, 3), 0.01, state.held.device)
        pos[..., 2] += 0.08  # dropped from 8 cm above the palm centre
        return pos

    def step(self, state: HoldState, inputs: TaskInputs) -> StepResult:
        touched = inputs.ball_contact[:, 0]
        state.held = state.held + touched
        dropped = inputs.ball_pos[:, 0, 2] < -PALM_DROP_LIMIT
        return StepResult(reward_terms={"hold": touched.to(inputs.ball_pos.dtype)}, terminated=dropped)

    def metrics(self, state: HoldState) -> dict[str, torch.Tensor]:
        return {"held": state.held}

    def observation(self, state: HoldState) -> torch.Tensor:
        return (state.held / 600.0)[:, None].to(torch.float64)

    def markers(self, state: HoldState) -> list:
        return []

    def path_metrics(self, ball_path: torch.Tensor, metrics: Mapping[str, float]) -> dict[str, float]:
        return {}

    def set_parameter(self, state: HoldState, name: str, value: float | torch.Tensor) -> None:
        set_state_parameter(state, {}, name, value)

    def derived_metrics(self, episode: Mapping[str, float]) -> dict[str, float]:
        return {}

    def path_kind(self, means: Mapping[str, float]) -> str | None:
        return None


@pytest.fixture
def hold_task(monkeypatch):
    monkeypatch.setitem(roto.tasks.TASKS, "hold", Hold())


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_a_new_task_runs_on_every_hand_and_ends_its_episodes(robot, hold_task):
    env = roto.make("hold", robot=robot, num_envs=3, seed=0, obs_mode="state", extra_groups=("task",), episode_steps=40)
    obs, _ = env.reset()
    assert obs["task"].shape == (3, 4 * 2) and obs["privileged"].shape == (3, 4 * 6)
    ended, held = 0, []
    for _ in range(45):
        obs, reward, _, _, info = env.step(torch.zeros(3, env.num_actions))
        assert reward.shape == (3,) and set(info["reward_terms"]) == {"hold"}
        if "episode" in info:
            done = info["_episode"]
            ended += int(done.sum())
            held += info["episode"]["held"][done].tolist()
    assert ended >= 3 and all(0 <= h <= 40 for h in held) and max(held) > 0  # the cupped hand holds it a while
    env.close()


def test_a_new_task_trains_with_roto_s_ppo(hold_task, tmp_path):
    from roto.rl.run_spec import build_run_spec
    from roto.rl.runner import Trainer

    config = tmp_path / "hold.yaml"  # a new task's default config is roto/configs/<task>.yaml; here, a file
    config.write_text("extends: bounce\n")
    tiny = ["env.episode_steps=8", "ppo.rollouts=8", "run.num_eval_envs=1", "network.encoder=[16]"]
    with pytest.raises(ValueError, match=r"task 'hold' has no packaged default agent config"):
        build_run_spec("hold", "allegro", "blind", None, tiny, 2 * 8, num_envs=2)
    spec = build_run_spec("hold", "allegro", "blind", str(config), tiny, 2 * 8, num_envs=2)
    with Trainer.open(tmp_path / "run", spec, tensorboard=False) as trainer:
        trainer.train(progress=False)
        assert trainer.update == 1 and trainer.last_eval["eval/held_mean"] >= 0.0

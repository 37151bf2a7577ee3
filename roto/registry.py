"""``roto.make``, ``roto.list_envs`` and the Gymnasium ids (``roto/Bounce-Shadow-v0``, ...)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from roto.robots import ROBOTS, get_robot
from roto.tasks import TASKS, get_task

if TYPE_CHECKING:
    from roto.envs.roto_env import RotoEnv


def make(
    task: str,
    robot: str = "shadow",
    num_envs: int = 1,
    obs_mode: str = "blind",
    backend: str = "cpu",
    device: str = "cpu",
    seed: int = 0,
    **options: object,
) -> RotoEnv:
    """A batched roto environment (see ``roto.envs.config.EnvConfig`` for every option).

    Task and robot names are case-insensitive. Unknown names raise ``ValueError`` listing the
    valid ones.
    """
    from roto.envs.config import EnvConfig
    from roto.envs.roto_env import RotoEnv

    config = EnvConfig(
        task=get_task(task).name,
        robot=get_robot(robot).name,
        num_envs=num_envs,
        obs_mode=obs_mode,
        backend=backend,
        device=device,
        seed=seed,
        **options,  # type: ignore[arg-type]
    )
    return RotoEnv(config)


def list_envs() -> list[tuple[str, str]]:
    """Every available (task, robot) pair."""
    return [(task, robot) for task in TASKS for robot in ROBOTS]


def gym_id(task: str, robot: str) -> str:
    """Gymnasium id of a (task, robot) pair, e.g. ``roto/Bounce-Shadow-v0``; the version is the task's
    (``Task.version``, bumped whenever its dynamics, rewards, observations or terminations change)."""
    spec = get_task(task)
    return f"roto/{spec.display_name}-{get_robot(robot).display_name}-v{spec.version}"


def register_gymnasium_envs() -> None:
    """Register every pair with Gymnasium (string entry points; idempotent)."""
    import gymnasium

    for task, robot in list_envs():
        env_id = gym_id(task, robot)
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point="roto.envs.gym_adapters:RotoSingleEnv",
            vector_entry_point="roto.envs.gym_adapters:RotoVectorEnv",
            kwargs={"task": task, "robot": robot},
            disable_env_checker=True,
        )

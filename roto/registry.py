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

    Task and robot names are case-insensitive. Unknown names and options raise ``ValueError``
    listing the valid ones.
    """
    import dataclasses

    from roto.envs.aids.settings import LEGACY_FIELDS
    from roto.envs.config import EnvConfig
    from roto.envs.roto_env import RotoEnv

    valid = sorted(f.name for f in dataclasses.fields(EnvConfig) if f.name not in ("task", "robot"))
    unknown = sorted(set(options) - set(valid))
    if unknown:
        moved = [(name, *LEGACY_FIELDS[name]) for name in unknown if name in LEGACY_FIELDS]
        hint = [f"{name} is now aids={ {aid: {setting: '...'}} }" for name, aid, setting in moved]
        raise ValueError(f"unknown env option(s) {unknown}; valid options: {valid}" + "".join(f"; {h}" for h in hint))
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


def check_id_pair(env_id: str, task: str, robot: str) -> None:
    """Refuse a task or robot that contradicts the Gymnasium id ``env_id`` an env is made under
    (Gymnasium lets ``gymnasium.make(id, robot=...)`` override the id's own kwargs).

    Raises:
        ValueError naming the id, what it fixes, the contradicting kwargs and the id to use.
    """
    fixed = next((pair for pair in list_envs() if gym_id(*pair) == env_id), None)
    if fixed is None:
        raise ValueError(f"{env_id!r} is not a roto Gymnasium id; valid ids: {[gym_id(*p) for p in list_envs()]}")
    given = (get_task(task).name, get_robot(robot).name)
    if given != fixed:
        named = {"task": (task, fixed[0], given[0]), "robot": (robot, fixed[1], given[1])}
        wrong = {name: value for name, (value, own, mine) in named.items() if own != mine}
        raise ValueError(
            f"{env_id} is task {fixed[0]!r} on robot {fixed[1]!r}; the kwargs {wrong} contradict it: "
            f"make {gym_id(*given)} instead"
        )


def register_gymnasium_envs() -> None:
    """Register every pair with Gymnasium (string entry points; idempotent)."""
    import gymnasium

    for task, robot in list_envs():
        env_id = gym_id(task, robot)
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point="roto.wrappers.gymnasium_envs:RotoSingleEnv",
            vector_entry_point="roto.wrappers.gymnasium_envs:RotoVectorEnv",
            kwargs={"task": task, "robot": robot, "env_id": env_id},
            disable_env_checker=True,
        )

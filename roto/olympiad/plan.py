"""Olympiad plans: which cells (task, robot, obs mode, agent variant, seed) to train and evaluate.

A plan is a YAML file::

    steps: 5000000          # env steps per cell
    eval_episodes: 100      # episodes of the final and the best policy's evaluation
    num_envs: 128
    threads: 2
    variants:               # name -> per task: agent config (a file or packaged name; null or
      ppo:                  #   left out: the task's default) and overrides (agent keys, and env.*
        bounce: {agent_cfg: bounce_cpu, overrides: [ppo.entropy_coef=0.004]}  # keys such as env.touch)
        baoding: {overrides: [ppo.epochs=4], roto_agent: ppo}  # compared with roto v1's PPO
      force_touch:
        bounce: {agent_cfg: bounce_cpu, overrides: [ppo.entropy_coef=0.004, env.touch=force]}
      replayed:             # {robot} in an override or the agent config becomes each cell's hand
        baoding: {overrides: ["env.aids.replayed_starts.bank=starts/{robot}.npz", env.aids.replayed_starts.share=0.25]}
      recipe:               # each pair's packaged recipe, named in the hand's record (PairRecord.recipe)
        bounce: {agent_cfg: "{recipe}"}
    grids:                  # the cells: the union of these products
      - {tasks: [bounce], robots: [shadow, allegro], obs: [blind], variants: [ppo], seeds: [0, 1]}
      - {tasks: [baoding], robots: [allegro], obs: [blind], variants: [ppo], seeds: [0], steps: 20000000}
                            # a grid's own steps: its cells' budget instead of the plan's

The packaged plans are ``benchmark``, ``paper`` and ``smoke`` (``roto/configs/olympiad``); one-off
plans live in ``experiments/``. Everything a plan names is checked before anything runs.
"""

from __future__ import annotations

import fnmatch
import importlib.resources
import itertools
import pathlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from roto.envs.observations import OBS_MODES
from roto.rl.build import resolve_groups
from roto.rl.overrides import split_overrides
from roto.rl.run_spec import build_run_spec
from roto.robots import ROBOTS
from roto.sim.backend import BACKENDS
from roto.tasks import TASKS
from roto.value_checks import check_count
from roto.yaml_files import read_yaml

PLAN_KEYS = {"description", "steps", "eval_episodes", "num_envs", "threads", "backend", "device", "variants", "grids"}
VARIANT_KEYS = {"agent_cfg", "overrides", "roto_agent"}
"""Keys of a variant's entry for one task."""
ROTO_AGENTS = ("ppo", "forward_dynamics", "forward_dynamics_memory")
"""roto's published agents a variant may declare itself to be (``roto_agent``): its column then
stands beside that agent's roto v1 figure in ``roto results``; a variant that declares none (a
privileged critic, a swept config, another touch) stands beside none."""
GRID_KEYS = {"tasks", "robots", "obs", "variants", "seeds"}
"""A grid's lists, each required; a grid may also name its cells' ``steps``."""
ROBOT_FIELD = "{robot}"
"""Written in a variant's override or agent config, replaced by each cell's robot name."""
RECIPE_FIELD = "{recipe}"
"""Written as a variant's agent config: each cell's pair's packaged recipe (``PairRecord.recipe``)."""


@dataclass(frozen=True)
class VariantTask:
    """What a variant trains one task with."""

    task: str
    agent_cfg: str | None
    overrides: tuple[str, ...]
    roto_agent: str | None = None

    @property
    def label(self) -> str:
        """The agent config and overrides, as a results table names them."""
        changes = f" + {', '.join(self.overrides)}" if self.overrides else ""
        config = "each hand's recipe (its record's)" if self.agent_cfg == RECIPE_FIELD else self.agent_cfg
        return f"{config or self.task}{changes}"


@dataclass(frozen=True)
class Variant:
    """An agent: per task, its config (None: the task's default) and overrides."""

    name: str
    per_task: tuple[VariantTask, ...]

    def for_task(self, task: str) -> VariantTask:
        """What this variant trains ``task`` with."""
        for entry in self.per_task:
            if entry.task == task:
                return entry
        raise ValueError(
            f"variant {self.name!r} has no config for task {task!r}; it has {[e.task for e in self.per_task]}"
        )

    def agent_for(self, task: str, robot: str | None = None) -> tuple[str | None, list[str]]:
        """(agent config, overrides) this variant trains ``task`` with; with ``robot``, ``{robot}``
        in the agent config or an override becomes the robot's name (a per-hand config, a per-hand
        file such as replayed starts), and ``{recipe}`` as the agent config the pair's packaged
        recipe (``PairRecord.recipe``)."""
        entry = self.for_task(task)
        if robot is None:
            return entry.agent_cfg, list(entry.overrides)
        agent_cfg = entry.agent_cfg.replace(ROBOT_FIELD, robot) if entry.agent_cfg else entry.agent_cfg
        if agent_cfg == RECIPE_FIELD:
            agent_cfg = ROBOTS[robot].tasks[task].recipe
        return agent_cfg, [o.replace(ROBOT_FIELD, robot) for o in entry.overrides]


@dataclass(frozen=True, order=True)
class Cell:
    """One run of the Olympiad."""

    task: str
    robot: str
    obs: str
    variant: str
    seed: int

    @property
    def name(self) -> str:
        """``<task>-<robot>-<obs>-<variant>-seed<k>``: the run directory's and the summary's name."""
        return f"{self.task}-{self.robot}-{self.obs}-{self.variant}-seed{self.seed}"

    @classmethod
    def of_summary(cls, summary: dict) -> Cell:
        """The cell a cell summary (``roto.olympiad.cell.run_cell``'s) was trained as."""
        return cls(*(summary[key] for key in ("task", "robot", "obs", "variant", "seed")))


@dataclass(frozen=True)
class Plan:
    """A checked plan."""

    name: str
    steps: int
    eval_episodes: int
    num_envs: int
    threads: int
    variants: dict[str, Variant]
    cells: tuple[Cell, ...]
    backend: str = "cpu"
    device: str = "cpu"
    description: str = ""
    budgets: Mapping[str, int] = field(default_factory=dict)
    """{cell name: env steps} of the cells whose grid names its own ``steps``."""

    def steps_for(self, cell: Cell) -> int:
        """The env steps ``cell`` trains: its grid's ``steps``, else the plan's."""
        return self.budgets.get(cell.name, self.steps)


def packaged_plans() -> dict[str, pathlib.Path]:
    """{name: path} of the plans shipped in ``roto/configs/olympiad``."""
    folder = importlib.resources.files("roto") / "configs" / "olympiad"
    return {pathlib.Path(str(p)).stem: pathlib.Path(str(p)) for p in folder.iterdir() if p.name.endswith(".yaml")}


def load_plan(plan: str) -> Plan:
    """A packaged plan by name, or a plan file; ValueError naming any unknown key, name or value."""
    shipped = packaged_plans()
    path = shipped.get(plan) or pathlib.Path(plan)
    if not path.is_file():
        raise FileNotFoundError(f"plan {plan!r} does not exist; give a YAML file or a packaged plan: {sorted(shipped)}")
    data = read_yaml(path, "plan") or {}
    where = f"plan {plan!r}"
    _check_keys(data, PLAN_KEYS, where)
    numbers = {
        key: data.get(key, default)
        for key, default in (("steps", 5_000_000), ("eval_episodes", 100), ("num_envs", 128), ("threads", 1))
    }
    for key, value in numbers.items():
        check_count(f"{where}: {key}", value, 1)
    variants = {
        name: _variant(name, spec, f"{where}: variant {name!r}") for name, spec in (data.get("variants") or {}).items()
    }
    # in the plan's order, seed-major: every cell gets its first seed before any gets a second
    listed, budgets = [], {}
    for i, grid in enumerate(data.get("grids") or []):
        grid_cells, steps = _grid_cells(grid, variants, f"{where}: grids[{i}]")
        for cell in grid_cells:
            budget = numbers["steps"] if steps is None else steps
            if budgets.setdefault(cell.name, budget) != budget:
                raise ValueError(
                    f"{where}: grids[{i}] gives cell {cell.name} {budget} env steps, "
                    f"an earlier grid {budgets[cell.name]}; give each cell one budget"
                )
        listed += grid_cells
    cells = sorted(dict.fromkeys(listed), key=lambda cell: cell.seed)
    if not cells:
        raise ValueError(f"{where} has no cells: give at least one grid with tasks, robots, obs, variants, seeds")
    backend, device = str(data.get("backend", "cpu")), str(data.get("device", "cpu"))
    if backend not in BACKENDS:
        raise ValueError(f"{where}: unknown backend {backend!r}; valid backends: {list(BACKENDS)}")
    return Plan(
        name=path.stem,
        variants=variants,
        cells=tuple(cells),
        backend=backend,
        device=device,
        description=str(data.get("description", "")),
        budgets={name: steps for name, steps in budgets.items() if steps != numbers["steps"]},
        **numbers,
    )


def select_cells(plan: Plan, patterns: Sequence[str]) -> Plan:
    """``plan`` with only the cells whose names match one of ``patterns`` (shell-style, as
    ``fnmatch``: ``bounce-*``, ``*-state-*``, ``*-seed2``), in the plan's order; the plan itself
    without patterns. The name stays the plan's, so the cells chosen share its queue, run
    directories and results. ValueError naming a pattern that matches no cell."""
    for pattern in patterns:
        if not any(fnmatch.fnmatchcase(cell.name, pattern) for cell in plan.cells):
            examples = ", ".join(cell.name for cell in plan.cells[:3])
            raise ValueError(
                f"--only {pattern!r} matches none of the {len(plan.cells)} cells of plan {plan.name!r}; "
                f"a cell's name is task-hand-obs-variant-seedN (e.g. {examples}); "
                "patterns as fnmatch: 'bounce-*', '*-seed2'"
            )
    if not patterns:
        return plan
    chosen = tuple(c for c in plan.cells if any(fnmatch.fnmatchcase(c.name, p) for p in patterns))
    return replace(plan, cells=chosen)


def _check_keys(data: Any, valid: set[str], where: str) -> None:
    if not isinstance(data, dict):
        raise ValueError(f"{where} must be a mapping, got {data!r}")
    unknown = sorted(set(data) - valid)
    if unknown:
        raise ValueError(f"{where}: unknown keys {unknown}; valid keys: {sorted(valid)}")


def _variant(name: str, spec: Any, where: str) -> Variant:
    _check_keys(spec, set(TASKS), where)
    per_task = []
    for task, entry in spec.items():
        _check_keys(entry or {}, VARIANT_KEYS, f"{where}, task {task!r}")
        entry = entry or {}
        overrides = tuple(entry.get("overrides") or ())
        split_overrides([o.replace(ROBOT_FIELD, "robot") for o in overrides])  # env keys now, values per cell
        roto_agent = entry.get("roto_agent")
        if roto_agent is not None and roto_agent not in ROTO_AGENTS:
            raise ValueError(f"{where}, task {task!r}: unknown roto_agent {roto_agent!r}; valid: {list(ROTO_AGENTS)}")
        per_task.append(VariantTask(task, entry.get("agent_cfg"), overrides, roto_agent))
    return Variant(name, tuple(per_task))


def _grid_cells(grid: Any, variants: dict[str, Variant], where: str) -> tuple[list[Cell], int | None]:
    """The grid's cells and its own ``steps`` (None: the plan's)."""
    _check_keys(grid, GRID_KEYS | {"steps"}, where)
    steps = grid.get("steps")
    if steps is not None:
        check_count(f"{where}: steps", steps, 1)
    valid = {"tasks": sorted(TASKS), "robots": sorted(ROBOTS), "obs": list(OBS_MODES), "variants": sorted(variants)}
    for key in GRID_KEYS:
        values = grid.get(key)
        if not isinstance(values, list) or not values:
            raise ValueError(f"{where}: {key} must be a non-empty list, got {values!r}")
        for value in values if key != "seeds" else ():
            if value not in valid[key]:
                raise ValueError(
                    f"{where}: unknown {key[:-1] if key != 'obs' else 'obs mode'} {value!r}; valid {key}: {valid[key]}"
                )
    for seed in grid["seeds"]:
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise ValueError(f"{where}: seeds must be integers >= 0, got {seed!r}")
    for task, robot, obs, name in itertools.product(grid["tasks"], grid["robots"], grid["obs"], grid["variants"]):
        try:  # the variant's config and env overrides must hold for this pair and obs mode (groups included)
            spec = build_run_spec(task, robot, obs, *variants[name].agent_for(task, robot))
            resolve_groups(spec.agent, obs)
        except (ValueError, FileNotFoundError) as error:
            raise ValueError(f"{where}: variant {name!r} on {task}/{robot}/{obs}: {error}") from None
    values = itertools.product(grid["tasks"], grid["robots"], grid["obs"], grid["variants"], grid["seeds"])
    return [Cell(*v) for v in values], steps

"""Recorded states that training episodes may start from (reference-state initialisation).

A bank holds states recorded in one hand's scene, e.g. by the Baoding reference controller just
before its swaps (``roto demo --task baoding --preswap_out``): each state's physics (qpos and qvel),
the joint targets held then, and the task state fields the file carries (Baoding: ``swapped`` and
``latched``). The env draws a share of its episode starts from the bank (``ReplayedStartsSettings.share``)
instead of the task's own starts; evaluation never does.
"""

from __future__ import annotations

import dataclasses
import importlib.resources
import pathlib
import zipfile
import zlib
from dataclasses import dataclass

import mujoco
import numpy as np
import torch

from roto.artifact_formats import FORMAT_KEY, check_format
from roto.envs.config import EnvConfig
from roto.sim.mujoco_cpu import state_offsets


@dataclass(frozen=True)
class ReplayBank:
    """n recorded states: qpos (n, nq), qvel (n, nv), target (n, n_act) and task fields name -> (n, ...)."""

    qpos: torch.Tensor
    qvel: torch.Tensor
    target: torch.Tensor
    task: dict[str, torch.Tensor]

    def __len__(self) -> int:
        return len(self.qpos)

    def to(self, device: torch.device) -> ReplayBank:
        """The bank on ``device``."""
        return ReplayBank(
            self.qpos.to(device),
            self.qvel.to(device),
            self.target.to(device),
            {name: value.to(device) for name, value in self.task.items()},
        )

    def state_dict(self) -> dict[str, object]:
        """Copies of the bank's tensors (saved with the env, so a resume draws from the same states)."""
        return {
            "qpos": self.qpos.clone(),
            "qvel": self.qvel.clone(),
            "target": self.target.clone(),
            "task": dict(self.task),
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, object], device: torch.device) -> ReplayBank:
        """Inverse of ``state_dict``."""
        return cls(state["qpos"], state["qvel"], state["target"], state["task"]).to(device)


BANK_BOUND = 1e3
"""The largest magnitude a bank's value may have: recorded positions (m, rad), velocities and
joint targets of a hand the size of a hand stay far below it; NaN, inf or 1e30 are a broken file."""


def packaged_banks() -> dict[str, pathlib.Path]:
    """{name: file} of the banks roto ships (``roto/banks/<name>.npz``: each hand's reference
    controller's states before its swaps, ``roto demo --task baoding --preswap_out``)."""
    folder = importlib.resources.files("roto") / "banks"
    return {pathlib.Path(str(p)).stem: pathlib.Path(str(p)) for p in folder.iterdir() if p.name.endswith(".npz")}


def resolve_bank(bank: str | pathlib.Path) -> pathlib.Path:
    """The file of ``bank``: a packaged bank's name (no folder, no suffix: ``shadow_preswap``,
    ``packaged_banks``), or the path of an ``.npz`` (relative: to the current directory).

    Raises:
        ValueError for a name roto ships no bank under, listing those it ships.
    """
    text = str(bank)
    if "/" in text or "\\" in text or text.endswith(".npz"):
        return pathlib.Path(text)
    shipped = packaged_banks()
    if text not in shipped:
        raise ValueError(
            f"aids.replayed_starts.bank {text!r} is no bank roto ships; packaged banks: {sorted(shipped)} "
            "(or give the path of an .npz)"
        )
    return shipped[text]


def read_bank(path: str | pathlib.Path) -> dict[str, np.ndarray]:
    """The arrays of the ``.npz`` bank ``path`` (a packaged bank's name or a file, ``resolve_bank``),
    read without pickle.

    Raises:
        ValueError naming the file and what is wrong with it in one line (missing, a directory,
        not an ``.npz``, truncated or corrupted, or holding object arrays), never loading unsafely.
    """
    where = f"aids.replayed_starts.bank {str(path)!r}"
    path = resolve_bank(path)
    if not path.is_file():  # checked here, where it is read: a run's config stays loadable without it
        what = "is a directory" if path.is_dir() else "is not a file"
        raise ValueError(
            f"{where} {what} (a relative path is read from the current directory, {str(pathlib.Path.cwd())!r}; "
            "a bank roto ships is named without folder or suffix, e.g. 'shadow_preswap')"
        )
    with open(path, "rb") as file:
        head = file.read(6)
    if not head.startswith(b"PK"):  # an .npz is a zip archive of .npy arrays
        found = "a single .npy array" if head == b"\x93NUMPY" else f"a file starting {head!r}"
        raise ValueError(f"{where} is not an .npz archive of named arrays: found {found}")
    try:
        with np.load(path, allow_pickle=False) as saved:
            return {name: saved[name] for name in saved.files}
    except ValueError as error:
        if "pickle" not in str(error):
            raise
        raise ValueError(
            f"{where} holds object arrays (pickled Python objects), which roto never loads; banks hold "
            "plain arrays, as `roto demo --task baoding --preswap_out` writes them"
        ) from None
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, KeyError) as error:
        reason = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise ValueError(f"{where} is truncated or corrupted, not a readable .npz: {reason}") from None


def check_bank(path: str, arrays: dict[str, np.ndarray], task: str, robot: str, sizes: tuple[int, int]) -> None:
    """Refuse a bank recorded on another task or robot, of another shape than ``sizes`` (state
    values, actions) or with a value that is not finite or beyond ``BANK_BOUND``.

    Raises:
        ValueError naming the file, what was expected and what was found.
    """
    where = f"aids.replayed_starts.bank {path!r}"
    found = arrays.get(FORMAT_KEY)
    check_format("bank", None if found is None else found.item(), where)
    for name, own in (("task", task), ("robot", robot)):  # a bank without the entry: its shapes must fit
        if name in arrays and str(arrays[name]) != own:
            raise ValueError(f"{where}: states recorded on {name} {str(arrays[name])!r}, not this env's {own!r}")
    physics, target = arrays.get("physics"), arrays.get("target")
    if physics is None or target is None or physics.ndim != 2 or len(physics) == 0:
        raise ValueError(f"{where}: needs non-empty arrays 'physics' (n, nstate) and 'target'")
    nstate, num_actions = sizes
    if physics.shape[1] != nstate or target.shape != (len(physics), num_actions):
        raise ValueError(
            f"{where}: states of {physics.shape[1]} values and targets of shape {target.shape} do not "
            f"fit this scene ({nstate} values, {num_actions} actions)"
        )
    for name in ("physics", "target"):
        values = arrays[name]
        if not np.issubdtype(values.dtype, np.number):
            raise ValueError(f"{where}: array {name!r} holds {values.dtype} values, not numbers")
        bad = ~np.isfinite(values) | (np.abs(values) > BANK_BOUND)
        if bad.any():
            row, column = np.argwhere(bad)[0]
            raise ValueError(
                f"{where}: array {name!r} holds {int(bad.sum())} values that are not finite or beyond "
                f"+-{BANK_BOUND:g} (first: {float(values[row, column])} in state {row}); a bank holds recorded states"
            )


def load_replay_bank(
    path: str, model: mujoco.MjModel, robot: str, task: str, task_state: object, num_actions: int
) -> ReplayBank:
    """The states of ``path`` (arrays ``physics`` (n, nstate) ``mjSTATE_FULLPHYSICS``, ``target``
    (n, n_act), ``robot``, ``task`` and task state fields) for ``model`` of ``robot`` in ``task``;
    task fields are the arrays named like a field of ``task_state``.

    Raises:
        ValueError naming the file when it is missing, unreadable, of another robot, task or model,
        holds no state or values no hand records (``check_bank``).
    """
    arrays = read_bank(path)
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS.value)
    check_bank(path, arrays, task, robot, (nstate, num_actions))
    physics, target = arrays["physics"], arrays["target"]
    qpos0, qvel0 = state_offsets(model)
    fields = {f.name for f in dataclasses.fields(task_state)}
    return ReplayBank(
        qpos=torch.from_numpy(physics[:, qpos0 : qpos0 + model.nq].copy()),
        qvel=torch.from_numpy(physics[:, qvel0 : qvel0 + model.nv].copy()),
        target=torch.from_numpy(target.astype(np.float64)),
        task={name: torch.from_numpy(value.copy()) for name, value in arrays.items() if name in fields},
    )


def check_replay_starts(config: EnvConfig) -> None:
    """Read and check the bank ``config`` names against its hand's scene as its envs will, without
    building them: so a run, a plan or a sweep is refused before it creates anything."""
    replayed = config.aids.replayed_starts
    if replayed is None:
        return
    from roto.robots import get_robot
    from roto.sim.scene import build_scene
    from roto.tasks import get_task

    task, robot = get_task(config.task), get_robot(config.robot)
    model, _ = build_scene(robot, task.balls(robot), config.touch)
    state = task.init_state(robot, 1, torch.device("cpu"))
    load_replay_bank(replayed.bank, model, robot.name, task.name, state, robot.num_actions)

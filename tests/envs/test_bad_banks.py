"""Banks of replayed starts that are not what roto records: each is refused in one line naming the
file and what is wrong, when the env is made and before a run, a plan's cell or a sweep exists;
no refusal advises loading unsafely."""

import io
import pathlib
import zipfile

import numpy as np
import pytest

import roto
from roto.cli import main
from tests.conftest import SHADOW_BANK


def good_arrays():
    with np.load(SHADOW_BANK) as saved:
        return {name: saved[name] for name in saved.files}


def write_bank(path, **changes):
    arrays = {**good_arrays(), **changes}
    np.savez(path, **{name: value for name, value in arrays.items() if value is not None})
    return path


def npy_bytes(array):
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def nan_states(arrays):
    physics = arrays["physics"].copy()
    physics[3, 7] = np.nan
    return physics


def truncated(path):
    data = pathlib.Path(SHADOW_BANK).read_bytes()
    path.write_bytes(data[: len(data) // 2])
    return path


def corrupted(path):
    write_bank(path)
    with zipfile.ZipFile(path) as archive:  # flip bytes inside the first member's compressed data
        info = archive.infolist()[0]
    data = bytearray(path.read_bytes())
    start = info.header_offset + 30 + len(info.filename) + len(info.extra)
    data[start + 10 : start + 60] = bytes(50)
    path.write_bytes(bytes(data))
    return path


def compressed_corrupted(path):
    arrays = good_arrays()
    np.savez_compressed(path, **arrays)
    with zipfile.ZipFile(path) as archive:
        info = archive.getinfo("physics.npy")
    data = bytearray(path.read_bytes())
    start = info.header_offset + 30 + len(info.filename) + len(info.extra)
    data[start + 20 : start + 200] = bytes(range(180))
    path.write_bytes(bytes(data))
    return path


BANKS = {
    "a text file": (lambda p: (p.write_text("not a bank\n"), p)[1], "is not an .npz archive of named arrays"),
    "half a bank": (truncated, "is truncated or corrupted, not a readable .npz"),
    "a corrupted stored member": (corrupted, "aids.replayed_starts.bank"),
    "a corrupted compressed member": (compressed_corrupted, "is truncated or corrupted, not a readable .npz"),
    "object arrays": (
        lambda p: write_bank(p, robot=np.array(["shadow", None], dtype=object)),
        "holds object arrays (pickled Python objects), which roto never loads",
    ),
    "a NaN state": (lambda p: write_bank(p, physics=nan_states(good_arrays())), "values that are not finite"),
    "1e30 targets": (lambda p: write_bank(p, target=np.full_like(good_arrays()["target"], 1e30)), "beyond +-1000"),
    "another task": (lambda p: write_bank(p, task=np.array("bounce")), "recorded on task 'bounce', not this env's"),
    "another hand": (lambda p: write_bank(p, robot=np.array("orca")), "recorded on robot 'orca', not this env's"),
    "no states": (lambda p: write_bank(p, physics=None), "needs non-empty arrays 'physics'"),
    "a directory": (lambda p: p.mkdir() or p, "is a directory"),
    "one .npy array": (lambda p: (p.write_bytes(npy_bytes(np.zeros(3))), p)[1], "found a single .npy array"),
}


@pytest.mark.parametrize("case", BANKS)
def test_a_bad_bank_is_refused_by_the_env_naming_the_file(case, tmp_path):
    make_file, words = BANKS[case]
    path = make_file(tmp_path / "bank.npz")
    with pytest.raises(ValueError) as refused:
        roto.make("baoding", robot="shadow", num_envs=1, aids={"replayed_starts": {"bank": str(path), "share": 0.5}})
    message = str(refused.value)
    assert words in message and str(path) in message and "\n" not in message
    assert "allow_pickle" not in message and "unsafe" not in message


@pytest.mark.parametrize("case", ["a text file", "a NaN state", "another hand"])
def test_roto_train_refuses_a_bad_bank_before_its_run_directory_exists(case, tmp_path, capsys):
    path = BANKS[case][0](tmp_path / "bank.npz")
    run_dir = tmp_path / "run"
    args = ["train", "--task", "baoding", "--steps", "16", "--run_dir", str(run_dir), "--no_progress"]
    assert main([*args, f"env.aids.replayed_starts.bank={path}", "env.aids.replayed_starts.share=0.5"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and BANKS[case][1] in err and "Traceback" not in err
    assert not run_dir.exists()


def test_a_plan_whose_bank_is_missing_for_one_hand_is_refused_by_its_check_and_dry_run(tmp_path, capsys):
    starts = tmp_path / "starts"
    starts.mkdir()
    write_bank(starts / "shadow.npz")  # the Allegro's is missing
    plan = tmp_path / "plan.yaml"
    plan.write_text(
        "variants:\n  ppo:\n    baoding: {agent_cfg: baoding, overrides: "
        f'["env.aids.replayed_starts.bank={starts}/{{robot}}.npz", env.aids.replayed_starts.share=0.5]}}\n'
        "grids:\n  - {tasks: [baoding], robots: [shadow, allegro], obs: [blind], variants: [ppo], seeds: [0]}\n"
    )
    for extra in (["--dry-run"], []):
        assert main(["olympiad", str(plan), "--root", str(tmp_path / "o"), *extra]) == 2
        err = capsys.readouterr().err
        assert f"aids.replayed_starts.bank '{starts}/allegro.npz' is not a file" in err and err.count("\n") == 1
    assert not (tmp_path / "o").exists()


def test_a_sweep_with_a_bad_bank_creates_no_study_so_the_fixed_command_runs(tmp_path, capsys):
    bad = BANKS["a NaN state"][0](tmp_path / "bad.npz")
    root = tmp_path / "sweeps"
    args = ["sweep", "--study", "s", "--root", str(root), "--task", "baoding", "--trials", "1", "--steps", "16"]
    assert (
        main([*args, "--set", f"env.aids.replayed_starts.bank={bad}", "--set", "env.aids.replayed_starts.share=0.5"])
        == 2
    )
    assert "values that are not finite" in capsys.readouterr().err
    assert not (root / "s").exists()

"""``roto train --logger wandb``: an offline W&B run gets the CSV's scalars, and ``--resume`` continues it."""

import csv
import struct
import sys

import pytest
import yaml

from roto.cli import build_parser, main
from tests.conftest import require_extra
from tests.test_cli_training import TINY

require_extra("wandb", "wandb")

BLOCK = 32 * 1024
"""The .wandb file is a LevelDB log: 32 KiB blocks of (crc, length, type) + payload chunks."""
FULL, LAST = 1, 4


def wandb_records(run_file):
    """The protobuf records of an offline run's ``run-<id>.wandb`` file (after its 7-byte W&B header)."""
    from wandb.proto.wandb_internal_pb2 import Record

    data = run_file.read_bytes()
    assert data[:4] == b":W&B"
    pos, chunk = 7, b""
    while pos + 7 <= len(data):
        if BLOCK - pos % BLOCK < 7:  # a block's tail too short for a header is padding
            pos += BLOCK - pos % BLOCK
            continue
        _crc, length, kind = struct.unpack("<IHB", data[pos : pos + 7])
        chunk += data[pos + 7 : pos + 7 + length]
        pos += 7 + length
        if kind in (FULL, LAST):
            yield Record.FromString(chunk)
            chunk = b""


def offline_runs(run_dir):
    """{offline run folder name: (run record, {(env_steps, tag): value})} of a roto run directory."""
    runs = {}
    for folder in sorted((run_dir / "wandb").glob("offline-run-*")):
        run, history = None, {}
        for record in wandb_records(next(folder.glob("run-*.wandb"))):
            if record.HasField("run"):
                run = record.run
            elif record.HasField("history"):
                for item in record.history.item:
                    tag = "/".join(item.nested_key) or item.key
                    if not tag.startswith("_"):
                        history[(record.history.step.num, tag)] = float(item.value_json)
        runs[folder.name] = (run, history)
    return runs


def csv_scalars(run_dir):
    """{(env_steps, tag): value} of ``scalars.csv``."""
    with (run_dir / "scalars.csv").open() as f:
        return {(int(row["env_steps"]), row["tag"]): float(row["value"]) for row in csv.DictReader(f)}


@pytest.fixture(scope="module")
def wandb_run(tmp_path_factory):
    """A tiny CLI training run logged to an offline W&B run, nothing of W&B's written outside tmp."""
    root = tmp_path_factory.mktemp("wandb")
    env = {"WANDB_MODE": "offline", "WANDB_SILENT": "true", "WANDB_DIR": root}
    env.update({f"WANDB_{name}_DIR": root / name.lower() for name in ("CONFIG", "CACHE", "DATA")})
    with pytest.MonkeyPatch.context() as patch:
        for name, value in env.items():
            patch.setenv(name, str(value))
        run_dir = root / "run"
        args = ["train", "--num_envs", "4", "--steps", "48", "--run_dir", str(run_dir), "--no_progress"]
        assert main([*args, "--logger", "wandb", *TINY]) == 0
        yield run_dir


def test_wandb_gets_the_csv_scalars_at_the_same_env_steps(wandb_run):
    runs = offline_runs(wandb_run)
    logged = {key: value for _, history in runs.values() for key, value in history.items()}
    expected = csv_scalars(wandb_run)
    assert logged.keys() == expected.keys()
    assert all(logged[key] == pytest.approx(expected[key], rel=1e-6) for key in expected)
    tags = {tag for _, tag in logged}
    assert {"loss/total", "ppo/approx_kl", "eval/return_mean", "perf/steps_per_s"} <= tags
    assert {step for step, tag in logged if tag == "loss/total"} >= {16, 32, 48}
    assert (wandb_run / "tensorboard").is_dir()  # W&B is in addition to TensorBoard


def test_the_wandb_run_is_named_after_the_run_and_holds_its_config(wandb_run):
    stored = yaml.safe_load((wandb_run / "wandb.yaml").read_text())
    runs = offline_runs(wandb_run)
    run, _ = runs[min(runs)]  # the first W&B session (the resume test may have added a second)
    assert (run.run_id, run.project, run.display_name) == (stored["id"], "roto", "run") and stored["project"] == "roto"
    config = {item.key: yaml.safe_load(item.value_json) for item in run.config.update}
    assert config["agent"]["ppo"]["rollouts"] == 4 and config["env"]["num_envs"] == 4


def test_resume_continues_the_same_wandb_run(wandb_run):
    stored = (wandb_run / "wandb.yaml").read_text()
    assert main(["train", "--resume", str(wandb_run), "--steps", "64", "--no_progress"]) == 0  # no --logger
    runs = offline_runs(wandb_run)
    assert len(runs) == 2 and (wandb_run / "wandb.yaml").read_text() == stored
    assert {run.run_id for run, _ in runs.values()} == {yaml.safe_load(stored)["id"]}
    _, resumed = runs[max(runs, key=lambda name: (len(name), name))]  # offline-run-<time>-<id>-1 if the same second
    assert {step for step, _ in resumed} == {64}


def test_missing_wandb_is_a_clear_error(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "wandb", None)  # what importlib finds when wandb is not installed
    run_dir = tmp_path / "run"
    assert main(["train", "--steps", "16", "--run_dir", str(run_dir), "--logger", "wandb"]) == 2
    assert "pip install -e '.[wandb]'" in capsys.readouterr().err
    assert not run_dir.exists()


def test_tensorboard_is_the_default_and_an_unknown_logger_is_a_usage_error(capsys):
    assert build_parser().parse_args(["train"]).logger == "tensorboard"
    with pytest.raises(SystemExit) as error:
        build_parser().parse_args(["train", "--logger", "mlflow"])
    assert error.value.code == 2 and "invalid choice: 'mlflow'" in capsys.readouterr().err

"""Every file roto reads back carries a format version, and a format this roto does not know is
refused in one line naming the file, never misread."""

import json
import pathlib

import numpy as np
import pytest
import torch
import yaml

import roto
from roto.artifact_formats import FORMATS, check_format
from roto.envs.config import EnvConfig
from roto.olympiad.results import check_summary
from roto.rl.checkpoints import load_checkpoint, save_checkpoint
from roto.rl.config import AgentConfig
from roto.rl.run_config import read_run_config, write_run_config
from roto.rl.run_spec import RunSpec
from tests.conftest import SHADOW_BANK

ROOT = pathlib.Path(__file__).resolve().parents[1]
SUMMARY = ROOT / "benchmarks" / "results" / "benchmark" / "cells" / "bounce-shadow-blind-ppo-seed0.json"


def newer_checkpoint(path):
    save_checkpoint({"format": 99, "model": {}, "train": {}, "agent": {}}, path)
    return lambda: load_checkpoint(path)


def newer_run_config(path):
    write_run_config(path, RunSpec(env=EnvConfig(task="bounce"), agent=AgentConfig(), steps=16))
    config = yaml.safe_load((path / "config.yaml").read_text())
    assert config["format"] == FORMATS["run config"]  # what roto writes now
    (path / "config.yaml").write_text(yaml.safe_dump({**config, "format": 99}))
    return lambda: read_run_config(path)


def newer_summary(path):
    summary = {**json.loads(SUMMARY.read_text()), "format": 99}
    return lambda: check_summary(path / "s.json", summary)


def newer_bank(path):
    with np.load(SHADOW_BANK) as saved:
        np.savez(path / "bank.npz", **{name: saved[name] for name in saved.files}, format=np.array(99))
    return lambda: roto.make("baoding", aids={"replayed_starts": {"bank": str(path / "bank.npz"), "share": 0.5}})


NEWER = {"checkpoint": newer_checkpoint, "run config": newer_run_config, "cell summary": newer_summary}
NEWER["bank"] = newer_bank


@pytest.mark.parametrize(("kind", "newer"), NEWER.items())
def test_a_newer_format_is_refused_naming_the_file(kind, newer, tmp_path):
    target = tmp_path / "c.pt" if kind == "checkpoint" else tmp_path
    read = newer(target)
    with pytest.raises(ValueError) as refused:
        read()
    message = str(refused.value)
    assert f"of format 99; this roto reads {kind} formats 1 to {FORMATS[kind]}" in message and str(tmp_path) in message
    assert "\n" not in message


def test_a_file_without_a_format_predates_them_and_reads_as_before(tmp_path):
    check_format("checkpoint", None, "old.pt")  # no entry: format 1's layout
    save_checkpoint({"model": {"w": torch.ones(1)}, "train": {}, "agent": {}}, tmp_path / "old.pt")
    assert "format" not in load_checkpoint(tmp_path / "old.pt")
    with pytest.raises(ValueError, match="format True"):
        check_format("bank", True, "b.npz")


SHADOW_BANK_IN_REPO = "shadow_preswap"  # format 1 named it by its old path; roto ships it now


def test_a_format_1_run_config_with_flat_aid_fields_reads_into_the_aids_section(tmp_path):
    config = yaml.safe_load((pathlib.Path(__file__).parent / "data" / "run_config_format1.yaml").read_text())
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(config))
    settings = read_run_config(tmp_path)
    aids = settings.env.aids
    replayed = aids.replayed_starts
    assert (replayed.bank, replayed.share, replayed.record_lead) == (SHADOW_BANK_IN_REPO, 0.5, 10)
    assert (aids.tolerance.start, aids.tolerance.target) == (0.025, 2) and aids.round_swaps is None  # 0.0: off
    assert aids.turn_shaping.per_turn == 20 and settings.to_dict()["env"]["aids"] == aids.to_dict()
    assert RunSpec.from_dict(settings.to_dict()) == settings and settings.steps == 5_000_000

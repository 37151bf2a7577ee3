import os
import pickle

import pytest
import torch

from roto.rl.checkpoints import load_checkpoint, save_checkpoint


class RunsCode:
    """Unpickling this calls os.system: what a malicious shared checkpoint could hold."""

    def __reduce__(self):
        return (os.system, ("touch pwned",))


def test_a_plain_checkpoint_round_trips(tmp_path):
    state = {"model": {"w": torch.ones(2)}, "train": {"total_steps": 5}, "agent": {"ppo": {"lr": 1e-3}},
             "best": float("-inf"), "flags": [True, None, "text"]}  # fmt: skip
    save_checkpoint(state, tmp_path / "c.pt")
    loaded = load_checkpoint(tmp_path / "c.pt")
    assert torch.equal(loaded["model"]["w"], torch.ones(2)) and loaded["flags"] == [True, None, "text"]
    assert not (tmp_path / "c.tmp").exists()


def test_a_crafted_pickle_is_refused_without_running_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    torch.save({"model": RunsCode(), "train": {}, "agent": {}}, tmp_path / "evil.pt")
    with pytest.raises(ValueError, match="is not a roto checkpoint"):
        load_checkpoint(tmp_path / "evil.pt")
    assert not (tmp_path / "pwned").exists()
    (tmp_path / "raw.pkl").write_bytes(pickle.dumps(RunsCode()))
    with pytest.raises(ValueError, match="is not a roto checkpoint"):
        load_checkpoint(tmp_path / "raw.pkl")
    assert not (tmp_path / "pwned").exists()


def test_files_that_are_not_roto_checkpoints_are_clear_errors(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(ValueError, match=r"notes\.txt' is not a roto checkpoint"):
        load_checkpoint(tmp_path / "notes.txt")
    torch.save({"weights": torch.ones(1)}, tmp_path / "other.pt")
    with pytest.raises(ValueError, match="lacks the model, train and agent"):
        load_checkpoint(tmp_path / "other.pt")
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_checkpoint(tmp_path / "missing.pt")

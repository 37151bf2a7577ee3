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
    with pytest.raises(ValueError, match="lacks the model and spec entries"):
        load_checkpoint(tmp_path / "other.pt")
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_checkpoint(tmp_path / "missing.pt")


def broken_copies(tmp_path):
    """{case: (path, words)}: a good checkpoint truncated, with bytes zeroed, holding an object,
    and a directory."""
    save_checkpoint({"model": {"w": torch.ones(4096)}, "train": {}, "agent": {}}, tmp_path / "good.pt")
    data = (tmp_path / "good.pt").read_bytes()
    (tmp_path / "half.pt").write_bytes(data[: len(data) // 2])
    zeroed = bytearray(data)
    zeroed[64:160] = bytes(96)
    (tmp_path / "zeroed.pt").write_bytes(bytes(zeroed))
    torch.save({"model": {}, "train": {}, "agent": {}, "x": RunsCode()}, tmp_path / "object.pt")
    (tmp_path / "folder.pt").mkdir()
    return {
        "truncated": (tmp_path / "half.pt", "is truncated or corrupted"),
        "zeroed bytes": (tmp_path / "zeroed.pt", "is not a roto checkpoint"),
        "an object": (tmp_path / "object.pt", "holds pickled objects beyond tensors, numbers and strings"),
        "a directory": (tmp_path / "folder.pt", "is a directory; give a .pt file in it"),
    }


def test_a_broken_checkpoint_is_one_line_naming_it_and_never_advises_unsafe_loading(tmp_path):
    for path, words in broken_copies(tmp_path).values():
        with pytest.raises((ValueError, IsADirectoryError)) as refused:
            load_checkpoint(path)
        message = str(refused.value)
        assert words in message and str(path) in message and "\n" not in message
        assert "weights_only" not in message and "trust" not in message and "unsafe" not in message.lower()

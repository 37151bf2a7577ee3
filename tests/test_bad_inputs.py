"""Bad input as a new user types it: every case is one line on stderr naming the value, file or URL
(password hidden), exit code 2 (bad input) or 1 (runtime failure), no traceback, nothing written.

Cases that need a trained run or a database live beside their features (tests/test_cli_training.py,
tests/sweep/); this table is the rest, end to end through ``roto``'s entry point.
"""

import os

import pytest

from roto.cli import main

MALFORMED = "ppo: {lr: 1e-3\nnetwork: [\n"


def write(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return str(path)


CASES = {
    "malformed agent config": (
        lambda d: ["train", "--steps", "16", "--agent_cfg", write(d / "bad.yaml", MALFORMED)],
        2,
        "is not valid YAML at line",
    ),
    "malformed search space": (
        lambda d: ["sweep", "--study", "s", "--root", str(d / "sweeps"), "--space", write(d / "space.yaml", MALFORMED)],
        2,
        "is not valid YAML at line",
    ),
    "malformed Olympiad plan": (
        lambda d: ["olympiad", write(d / "plan.yaml", MALFORMED), "--root", str(d / "o")],
        2,
        "is not valid YAML at line",
    ),
    "a billion envs": (lambda d: ["train", "--steps", "16", "--num_envs", "1000000000"], 2, "1000000000"),
    "zero torch threads": (lambda d: ["train", "--steps", "16", "--torch_threads", "0"], 2, "--torch_threads"),
    "negative C threads": (lambda d: ["train", "--steps", "16", "--threads", "-1"], 2, "-1"),
    "video at a directory": (
        lambda d: ["play", "--checkpoint", "x.pt", "--video", str(d)],
        2,
        "is a directory",
    ),
    "video under a file": (
        lambda d: ["play", "--checkpoint", "x.pt", "--video", write(d / "file", "") + "/v.mp4"],
        2,
        "is not a directory",
    ),
    "unknown storage scheme": (
        lambda d: ["sweep", "show", "--study", "s", "--storage", "nosuchdb://u:secret@host/db"],
        2,
        "nosuchdb://u:***@host/db",
    ),
    "malformed storage URL": (lambda d: ["sweep", "show", "--study", "s", "--storage", "postgresql://"], 2, "storage"),
    "database port closed": (
        lambda d: ["sweep", "show", "--study", "s", "--storage", "postgresql+psycopg2://u:secret@127.0.0.1:1/db"],
        2,
        "postgresql+psycopg2://u:***@127.0.0.1:1/db",
    ),
    "database password with / # ?": (
        lambda d: ["sweep", "show", "--study", "s", "--storage", "postgresql+psycopg2://u:p/a#secret?@127.0.0.1:1/db"],
        2,
        "postgresql+psycopg2://u:***@127.0.0.1:1/db",
    ),
    "database password as a parameter": (
        lambda d: ["sweep", "show", "--study", "s", "--storage", "postgresql://u@127.0.0.1:1/db?Password=secret"],
        2,
        "postgresql://u@127.0.0.1:1/db?Password=***",
    ),
    "study name climbing out of the root": (
        lambda d: ["sweep", "--study", "..", "--root", str(d / "sweeps")],
        2,
        "plain name",
    ),
    "two workers, bad space": (
        lambda d: ["sweep", "--study", "s", "--root", str(d / "sweeps"), "--workers", "2", "--space", "nosuch"],
        2,
        "nosuch",
    ),
    "zero workers": (lambda d: ["olympiad", "benchmark", "--root", str(d / "o"), "--workers", "0"], 2, "--workers"),
    "zero torch threads per cell": (
        lambda d: ["olympiad", "benchmark", "--root", str(d / "o"), "--torch_threads", "0", "--dry-run"],
        2,
        "--torch_threads must be an integer >= 1, got 0",
    ),
    "a heartbeat of no time": (
        lambda d: ["olympiad", "benchmark", "--root", str(d / "o"), "--heartbeat", "0"],
        2,
        "--heartbeat must be a number of seconds > 0, got 0.0",
    ),
    "negative torch threads per trial": (
        lambda d: ["sweep", "--study", "s", "--root", str(d / "sweeps"), "--torch_threads", "-2"],
        2,
        "--torch_threads must be an integer >= 1, got -2",
    ),
    "a plan's results folder that is a file": (
        lambda d: ["olympiad", "smoke", "--root", str(d / "o"), "--results", write(d / "results", "")],
        2,
        "--results '",
    ),
    "a run directory that is a file": (
        lambda d: ["train", "--steps", "16", "--run_dir", write(d / "run", "")],
        2,
        "is a file; give a directory",
    ),
    "a sweep's root that is a file": (
        lambda d: ["sweep", "--study", "s", "--root", write(d / "sweeps", ""), "--steps", "16"],
        2,
        "is a file; give a directory",
    ),
    "a page to refresh that is a folder": (
        lambda d: ["results", "--pages", str(d)],
        2,
        "cannot be read: it is a folder; give a file",
    ),
    "a submission to check that is a folder": (
        lambda d: ["results", "--check", str(d)],
        2,
        "cannot be read: it is a folder; give a file",
    ),
    "pre-swap states at a directory": (
        lambda d: ["demo", "--task", "baoding", "--preswap_out", str(d)],
        2,
        "is a directory; give a file path",
    ),
    "pre-swap states under a file": (
        lambda d: ["demo", "--task", "baoding", "--preswap_out", write(d / "file", "") + "/s.npz"],
        2,
        "is not a directory (it is a file)",
    ),
    "pre-swap states whose name with .npz is a directory": (
        lambda d: ["demo", "--task", "baoding", "--preswap_out", write(d / "s.npz" / "f", "").removesuffix(".npz/f")],
        2,
        "(.npz appended): ",
    ),
    "pre-swap states into new folders, unknown hand": (  # the folders made for the file are removed again
        lambda d: ["demo", "--task", "baoding", "--robot", "nosuch", "--preswap_out", str(d / "new" / "deeper" / "s")],
        2,
        "unknown robot 'nosuch'",
    ),
    "image at a directory": (lambda d: ["render", "--out", str(d)], 2, "is a directory; give a file path"),
    "image under a file": (
        lambda d: ["render", "--out", write(d / "file", "") + "/scene.png"],
        2,
        "is not a directory (it is a file)",
    ),
    "image of an unknown format": (lambda d: ["render", "--out", str(d / "scene.xyz")], 2, "['.png', '.jpg'"),
    "negative settle steps": (
        lambda d: ["render", "--settle_steps", "-5", "--out", str(d / "new" / "scene.png")],
        2,
        "settle_steps must be >= 0 control steps, got -5",
    ),
    "evaluation at a directory": (lambda d: ["eval", "--checkpoint", "x.pt", "--out", str(d)], 2, "is a directory"),
    "evaluation under a file": (
        lambda d: ["eval", "--checkpoint", "x.pt", "--out", write(d / "file", "") + "/e.json"],
        2,
        "is not a directory (it is a file)",
    ),
    "zero timed bench steps": (lambda d: ["bench", "--num_envs", "2", "--steps", "0"], 2, "--steps"),
    "negative timed bench steps": (lambda d: ["bench", "--num_envs", "2", "--steps", "-3"], 2, "got -3"),
}


@pytest.mark.parametrize("case", CASES)
def test_bad_input_is_one_line_and_writes_nothing(case, tmp_path, monkeypatch, capsys):
    if case.startswith("database") or case.endswith("storage URL"):
        pytest.importorskip("psycopg2")
    build, code, needle = CASES[case]
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    args = build(inputs)
    before = sorted(os.listdir(inputs))
    assert main(args) == code
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("roto "), err
    assert needle in lines[0] and "secret" not in err
    assert not os.listdir(work) and sorted(os.listdir(inputs)) == before  # nothing created or removed

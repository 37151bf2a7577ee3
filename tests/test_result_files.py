import json

import pytest

from roto.olympiad.results import read_summaries
from roto.result_files import read_json, replacing, write_text_atomic


def test_an_interrupted_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "summary.json"
    write_text_atomic(path, '{"old": 1}')
    with pytest.raises(KeyboardInterrupt), replacing(path) as temporary:
        temporary.write_text('{"new": ')
        raise KeyboardInterrupt  # Ctrl-C mid-write
    assert json.loads(path.read_text()) == {"old": 1}
    assert [p.name for p in tmp_path.iterdir()] == ["summary.json"]
    write_text_atomic(path, '{"new": 2}')
    assert read_json(path) == {"new": 2} and [p.name for p in tmp_path.iterdir()] == ["summary.json"]


def test_a_torn_json_file_is_an_error_naming_the_file_and_the_place(tmp_path):
    path = tmp_path / "bounce-shadow-blind-ppo-seed0.json"
    path.write_text('{"task": "bounce",\n "final": {"return_')
    with pytest.raises(ValueError, match=r"cell summary '.*seed0\.json' is not valid JSON at line 2, column"):
        read_summaries(tmp_path)
    with pytest.raises(FileNotFoundError, match=r"eval JSON '.*missing\.json' does not exist"):
        read_json(tmp_path / "missing.json", "eval JSON")

"""evaluations.jsonl survives a crash mid-write: a torn last line is skipped (with a warning), a
broken line elsewhere names the file, and a resume rewrites the file atomically."""

import json

import pytest

from roto.rl.evaluation import EVALUATIONS_NAME, PolicyEvaluator, read_evaluations


def write(run_dir, *lines):
    (run_dir / EVALUATIONS_NAME).write_text("".join(line + "\n" for line in lines))


def record(update):
    return json.dumps({"update": update, "return_mean": float(update)})


def test_a_torn_last_line_is_skipped_with_a_warning(tmp_path):
    write(tmp_path, record(1), record(2), '{"update": 3, "retu')
    with pytest.warns(UserWarning, match="skipped a torn last line"):
        records = read_evaluations(tmp_path)
    assert [r["update"] for r in records] == [1, 2]


def test_a_broken_line_before_the_last_names_the_file_and_line(tmp_path):
    write(tmp_path, record(1), "not json", record(3))
    with pytest.raises(ValueError, match=rf"{EVALUATIONS_NAME}' line 2 is not a JSON record"):
        read_evaluations(tmp_path)


def test_resume_drops_later_records_and_the_torn_line(tmp_path):
    write(tmp_path, record(1), record(2), record(3), '{"upd')
    evaluator = PolicyEvaluator(env=None, seed=0, run_dir=tmp_path)
    with pytest.warns(UserWarning):
        evaluator.drop_after(2)
    assert (tmp_path / EVALUATIONS_NAME).read_text() == record(1) + "\n" + record(2) + "\n"
    assert not list(tmp_path.glob("*.tmp"))

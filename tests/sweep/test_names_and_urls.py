"""Study names stay inside --root, and no message shows a database password."""

import pytest

from roto.sweep import study as study_module
from roto.sweep.storage import redact_url
from roto.sweep.study import check_study_name, load_existing_study


@pytest.mark.parametrize("name", ["..", ".", "a/b", "../outside", "", "two words", "x\\y"])
def test_a_study_name_that_is_not_a_plain_name_is_refused(name):
    with pytest.raises(ValueError, match="the study name must be a plain name"):
        check_study_name(name)


@pytest.mark.parametrize("name", ["bounce_shadow", "quickstart-cpu.v2", "s1"])
def test_plain_names_pass(name):
    check_study_name(name)


def test_passwords_are_redacted_and_other_urls_untouched():
    assert redact_url("postgresql+psycopg2://roto:s3cret@db.example:5432/sweeps") == (
        "postgresql+psycopg2://roto:***@db.example:5432/sweeps"
    )
    assert redact_url("sqlite:///runs/sweeps/x.db") == "sqlite:///runs/sweeps/x.db"
    assert redact_url("postgresql://roto@host/db") == "postgresql://roto@host/db"


def test_a_missing_study_in_a_database_is_reported_without_the_password(monkeypatch):
    monkeypatch.setattr(study_module, "find_study", lambda folder, name, url: None)
    with pytest.raises(ValueError) as error:
        load_existing_study("gone", "runs/sweeps", "postgresql://roto:s3cret@host/db")
    assert "s3cret" not in str(error.value) and "roto:***@host" in str(error.value)
    with pytest.raises(ValueError, match="plain name"):
        load_existing_study("..", "runs/sweeps", None)

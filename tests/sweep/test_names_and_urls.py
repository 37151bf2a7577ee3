"""Study names stay inside --root, and no message shows a database password."""

import pytest

from roto.jobs.storage import redact_url
from roto.sweep import study as study_module
from roto.sweep.settings import check_study_name
from roto.sweep.study import load_existing_study


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


def test_plain_postgresql_urls_reach_the_server_through_the_installed_driver(postgres_url, tmp_path):
    import optuna

    from roto.jobs.storage import open_storage

    plain = postgres_url.replace("postgresql+psycopg2://", "postgresql://")
    storage = open_storage(tmp_path, plain)  # the --help's example form
    optuna.create_study(study_name="plain_url", storage=storage)
    assert "plain_url" in [s.study_name for s in optuna.get_all_study_summaries(storage)]


def test_a_server_that_never_answers_times_out_with_a_clear_error(monkeypatch, tmp_path):
    import socket
    import time

    from roto.jobs import storage

    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)  # accepts connections, never answers
    monkeypatch.setattr(storage, "CONNECT_TIMEOUT_S", 2)
    url = f"postgresql://roto:s3cret@127.0.0.1:{listener.getsockname()[1]}/db"
    start = time.monotonic()
    with pytest.raises(ValueError, match=r"cannot open the storage 'postgresql://roto:\*\*\*@127.0.0.1:.*timeout"):
        storage.open_storage(tmp_path, url)
    assert time.monotonic() - start < 10
    listener.close()


def test_a_worker_killed_by_a_signal_fails_the_command_and_is_named(capsys):
    from roto.jobs.claims import worst_exit

    assert worst_exit([0, 0], [11, 12]) == 0 and capsys.readouterr().err == ""
    assert worst_exit([0, -9], [11, 12]) == 1
    assert "worker 2 of 2 (pid 12) was killed by SIGKILL" in capsys.readouterr().err
    assert worst_exit([2, -15, 0], [1, 2, 3]) == 2
    err = capsys.readouterr().err
    assert "worker 1 of 3 (pid 1) exited with 2" in err and "worker 2 of 3 (pid 2) was killed by SIGTERM" in err


def test_a_wrong_database_password_is_one_line_without_the_password(postgres_binaries, capsys):
    import pathlib
    import re

    import psycopg2

    from roto.cli import main
    from tests.sweep.postgres_server import running_server

    with running_server(postgres_binaries) as server:
        port = int(re.search(r":(\d+)/", server.url).group(1))
        connection = psycopg2.connect(host="127.0.0.1", port=port, user="roto", dbname="postgres")
        connection.autocommit = True
        with connection.cursor() as cursor:  # password logins from here on
            cursor.execute("ALTER USER roto PASSWORD 'right'")
            cursor.execute("SHOW hba_file")
            hba = pathlib.Path(cursor.fetchone()[0])
            hba.write_text(hba.read_text().replace(" trust", " scram-sha-256"))
            cursor.execute("SELECT pg_reload_conf()")
        connection.close()
        url = f"postgresql://roto:wrongpass@127.0.0.1:{port}/roto_test"
        assert main(["sweep", "show", "--study", "s", "--storage", url]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "password authentication failed" in err
    assert "wrongpass" not in err and f"roto:***@127.0.0.1:{port}" in err


def test_a_sigterm_to_the_launcher_is_passed_on_to_each_running_worker():
    """``kill`` of ``roto sweep/olympiad --workers N`` reaches the workers, which else would train on
    orphaned; the launcher waits for them."""
    import os
    import signal
    import subprocess
    import sys
    import threading

    from roto.jobs.claims import wait_passing_on_sigterm

    sleep = [sys.executable, "-c", "import time; time.sleep(60)"]
    done = subprocess.Popen([sys.executable, "-c", "pass"])
    done.wait()
    workers = [subprocess.Popen(sleep) for _ in range(2)]
    before = signal.getsignal(signal.SIGTERM)
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGTERM))
    timer.start()
    try:
        codes = wait_passing_on_sigterm([done, *workers])
    finally:
        timer.cancel()
        for worker in workers:
            worker.kill()
    assert codes == [0, -signal.SIGTERM, -signal.SIGTERM]
    assert signal.getsignal(signal.SIGTERM) is before

"""A database password never shows: not in messages (whatever characters it holds, wherever in the
URL it is), not on a worker's command line; and a role without privileges is told what it lacks."""

import importlib.util
import os
import subprocess
import time
import urllib.parse

import pytest
from optuna.exceptions import StorageInternalError

from roto.cli import main
from roto.jobs.storage import STORAGE_ENV, redact_url, resolve_storage, scrub

needs_psycopg2 = pytest.mark.skipif(
    importlib.util.find_spec("psycopg2") is None, reason="connects through psycopg2 (the postgres extra)"
)

LEFT, RIGHT = "Xq7", "Zk9"
"""Each test password is LEFT + characters + RIGHT: neither half may show after redaction."""
SPECIAL = ["@", ":", "/", "#", "?", "%", "&", "=", ";", "{", "}", "[", "]", " ", "+", "!", "$", "'", '"', "\\", ","]
PASSWORDS = [
    *(LEFT + c + RIGHT for c in SPECIAL),
    *(LEFT + seq + RIGHT for seq in ("%40", "%2F", "%3A", "@@", "://", "?password=", "/db?x=1&y=", "{}", "}{", "%")),
    f":{LEFT}{RIGHT}@",
    f"{LEFT}@{RIGHT}:",
]
FORMS = [
    "postgresql+psycopg2://roto:{p}@db.example:5432/sweeps",
    "postgresql://roto:{p}@[::1]:5432/sweeps?sslmode=require",
    "postgresql://user@domain:{p}@db.example/sweeps",
    "postgresql://roto@db.example/sweeps?password={p}",
    "postgresql://roto@db.example/sweeps?sslmode=require&PassWord={p}&application_name=x",
    "postgresql://roto@db.example/sweeps?sslpassword={p}",
    "postgresql://roto@db.example/sweeps?pass%77ord={p}",
    "postgresql://roto:{p}@db.example/sweeps?password={p}",
    "postgresql:/roto:{p}@db.example/sweeps",  # malformed: a slash short
    "postgresql//roto:{p}@db.example/sweeps",
    "roto:{p}@db.example",
    "host=db.example password={p} dbname=sweeps",  # libpq's form, not a URL
]


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("password", PASSWORDS)
def test_no_password_survives_redaction(form, password):
    url = form.format(p=password)
    shown = redact_url(url)
    assert LEFT not in shown and RIGHT not in shown, shown
    assert "***" in shown


@pytest.mark.parametrize("form", FORMS[:3])
@pytest.mark.parametrize("password", PASSWORDS)
def test_a_drivers_message_is_scrubbed_of_the_password_as_given_and_decoded(form, password):
    url = form.format(p=password)
    decoded = urllib.parse.unquote(password)
    said = scrub(f'password "{password}" or "{decoded}" refused', url)
    assert LEFT not in said and RIGHT not in said and said.count("***") == 2, said


def test_redaction_hides_the_password_only():
    assert redact_url("postgresql://roto:a/b#c?d@db:5432/sweeps") == "postgresql://roto:***@db:5432/sweeps"
    assert (
        redact_url("postgresql://roto:p@ss@db/sweeps?sslmode=require")
        == "postgresql://roto:***@db/sweeps?sslmode=require"
    )
    assert redact_url("postgresql://roto@db/s?sslmode=require&password=x&a=b") == (
        "postgresql://roto@db/s?sslmode=require&password=***"
    )
    assert redact_url("postgresql://roto:a/b?c") == "postgresql://roto:***"  # the host left out: no "@"
    plain = ["sqlite:///runs/x.db", "postgresql://roto@host/db", "postgresql://host:5432/db", "runs/j.log"]
    for url in [*plain, "postgresql://roto@[::1]:5432/db?sslmode=require&application_name=a"]:
        assert redact_url(url) == url


PORT_CLOSED = "postgresql+psycopg2://roto:{p}@127.0.0.1:1/db"
CLI_URLS = [
    *(PORT_CLOSED.format(p=LEFT + seq + RIGHT) for seq in ("/", "#", "?", "/ss#w?rd", "%40", "%2F", "{", "}", "{x}")),
    PORT_CLOSED.format(p=LEFT + "@" + RIGHT),  # SQLAlchemy would end the password at the @: refused
    PORT_CLOSED.format(p=LEFT + "@" + RIGHT + ":1"),  # ... and read the rest as a port
    f"postgresql+psycopg2://roto@127.0.0.1:1/db?password={LEFT}/{RIGHT}",
    f"postgresql+psycopg2://roto@127.0.0.1:1/db?PASSWORD={LEFT}%23{RIGHT}&sslmode=disable",
    f"postgresql+psycopg2://roto:{LEFT}{RIGHT}@[::1/db",  # malformed host
    f"postgresql+psycopg2://roto:{LEFT}{RIGHT}@127.0.0.1:99999/db",  # a port the driver refuses
    f"postgresql//roto:{LEFT}{RIGHT}@127.0.0.1/db",  # neither a URL nor a journal
    f"nosuchdb://roto:{LEFT}/{RIGHT}@host/db",
]


@needs_psycopg2
@pytest.mark.parametrize("command", ["show", "olympiad"])
@pytest.mark.parametrize("url", CLI_URLS)
def test_the_cli_never_prints_a_password(url, command, tmp_path, capsys):
    args = ["sweep", "show", "--study", "s"] if command == "show" else ["olympiad", "benchmark", "--dry-run"]
    assert main([*args, "--root", str(tmp_path), "--storage", url]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"roto {args[0]}: error: "), captured.err
    assert "***" in lines[0]
    assert LEFT not in captured.err + captured.out and RIGHT not in captured.err + captured.out


@needs_psycopg2
def test_storage_env_name_reads_the_url_from_the_environment(monkeypatch, capsys):
    monkeypatch.setenv("ROTO_TEST_DB", "postgresql+psycopg2://roto:Xq7/Zk9@127.0.0.1:1/db")
    assert resolve_storage("env:ROTO_TEST_DB") == "postgresql+psycopg2://roto:Xq7/Zk9@127.0.0.1:1/db"
    assert resolve_storage("runs/j.log") == "runs/j.log" and resolve_storage(None) is None
    assert main(["sweep", "show", "--study", "s", "--storage", "env:ROTO_TEST_DB"]) == 2
    err = capsys.readouterr().err
    assert "'postgresql+psycopg2://roto:***@127.0.0.1:1/db'" in err and "Connection refused" in err
    monkeypatch.delenv("ROTO_TEST_DB")
    assert main(["sweep", "show", "--study", "s", "--storage", "env:ROTO_TEST_DB"]) == 2
    assert "environment variable 'ROTO_TEST_DB' is not set" in capsys.readouterr().err


WORKER_URL = f"postgresql+psycopg2://roto:{LEFT}/{RIGHT}@127.0.0.1:1/db"


def _proc_list(pid: int, name: str) -> list[str]:
    """``/proc/<pid>/<name>`` (cmdline, environ) as its NUL-separated strings, once the new program
    has set it up (Popen returns while execve is still replacing the child: empty until then)."""
    deadline = time.monotonic() + 10
    while True:
        with open(f"/proc/{pid}/{name}", "rb") as f:
            parts = [part.decode() for part in f.read().split(b"\0") if part]
        if parts or time.monotonic() > deadline:
            return parts
        time.sleep(0.001)


def _spy_on_workers(monkeypatch, kill: bool) -> list[tuple[list[str], dict[str, str]]]:
    """Make ``subprocess.Popen`` record each started ``roto`` worker's command line and environment,
    read from /proc as any local user could read the command line, and kill it at once if ``kill``."""
    real, seen = subprocess.Popen, []

    def spy(args, **kwargs):
        process = real(args, **kwargs)
        if "roto.cli" in args:
            cmdline = _proc_list(process.pid, "cmdline")
            environ = dict(part.partition("=")[::2] for part in _proc_list(process.pid, "environ"))
            seen.append((cmdline, environ))
            if kill:
                process.kill()
        return process

    monkeypatch.setattr(subprocess, "Popen", spy)
    return seen


def _launch(command: str, tmp_path, monkeypatch) -> int:
    """``roto <command> ... --workers 2 --storage WORKER_URL`` with the launcher's own use of the
    database (creating the study, enqueuing cells) left out: only the workers connect."""
    if command == "sweep":
        monkeypatch.setattr("roto.sweep.study.open_study", lambda settings: (None, None))
        args = ["sweep", "--study", "s", "--trials", "1", "--steps", "64", "--num_envs", "1"]
    else:
        monkeypatch.setattr("roto.olympiad.worker.open_olympiad", lambda plan, root, url: (None, None))
        monkeypatch.setattr("roto.olympiad.worker.enqueue_missing", lambda study, plan, results: [])
        args = ["olympiad", "benchmark"]
    return main([*args, "--root", str(tmp_path), "--workers", "2", "--storage", WORKER_URL])


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc/PID/cmdline")
@pytest.mark.parametrize("command", ["sweep", "olympiad"])
def test_workers_get_the_storage_url_in_their_environment_not_on_their_command_line(
    command, tmp_path, monkeypatch, capsys
):
    monkeypatch.delenv(STORAGE_ENV, raising=False)
    seen = _spy_on_workers(monkeypatch, kill=True)
    assert _launch(command, tmp_path, monkeypatch) == 1  # the workers were killed
    assert len(seen) == 2
    for cmdline, environ in seen:
        assert not any(LEFT in part or RIGHT in part for part in cmdline), cmdline
        assert cmdline[cmdline.index("--storage") + 1] == f"env:{STORAGE_ENV}"
        assert environ[STORAGE_ENV] == WORKER_URL
    assert STORAGE_ENV not in os.environ  # the launcher's own environment is as it was
    assert "was killed by SIGKILL" in capsys.readouterr().err


@needs_psycopg2
@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc/PID/cmdline")
def test_a_sweep_worker_connects_to_the_url_it_got_through_its_environment(tmp_path, monkeypatch, capfd):
    seen = _spy_on_workers(monkeypatch, kill=False)
    assert _launch("sweep", tmp_path, monkeypatch) == 2  # each worker: the closed port, named, exit 2
    err = capfd.readouterr().err
    assert len(seen) == 2 and err.count("cannot open the storage 'postgresql+psycopg2://roto:***@127.0.0.1:1/db'") == 2
    assert LEFT not in err and not os.listdir(tmp_path)  # no journal: the workers used the database URL


def _insufficient_privilege() -> StorageInternalError:
    """What Optuna raises when PostgreSQL refuses the role a table: its generic message, caused by
    SQLAlchemy's ProgrammingError, whose ``orig`` is psycopg2's InsufficientPrivilege."""
    import psycopg2.errors
    import sqlalchemy.exc

    driver = psycopg2.errors.InsufficientPrivilege("permission denied for table studies\n")
    wrapped = sqlalchemy.exc.ProgrammingError("INSERT INTO studies ...", {}, driver)
    try:
        try:
            raise wrapped from driver
        except sqlalchemy.exc.SQLAlchemyError as error:
            raise StorageInternalError("An exception is raised during the commit. ...") from error
    except StorageInternalError as error:
        return error


class _Refusing:
    """A stand-in for Optuna's RDBStorage whose every call is refused as a role without privileges is."""

    def get_all_studies(self):
        raise _insufficient_privilege()


@needs_psycopg2
def test_a_refused_table_privilege_is_named_at_once_not_retried():
    from roto.cli_errors import error_exit
    from roto.jobs.retrying_storage import DatabasePermissionDenied, RetryingStorage, permission_error

    assert permission_error(_insufficient_privilege()) is not None
    assert permission_error(StorageInternalError("exceeding max length")) is None
    pauses = []
    storage = RetryingStorage(_Refusing(), "postgresql://weak:***@db/sweeps", sleep=pauses.append)
    with pytest.raises(DatabasePermissionDenied) as caught:
        storage.get_all_studies()
    message = str(caught.value)
    assert message.startswith("database 'postgresql://weak:***@db/sweeps': permission denied for table studies: ")
    assert "SELECT, INSERT, UPDATE and DELETE" in message and "\n" not in message and pauses == []
    assert error_exit(caught.value) == (2, "error")


def test_a_role_without_privileges_is_told_what_it_lacks(postgres_url, tmp_path, capsys):
    """On a real server: a role that may not read Optuna's tables, then one that may only read them."""
    import optuna
    import sqlalchemy

    from roto.jobs.retrying_storage import DatabasePermissionDenied
    from roto.jobs.storage import open_storage

    open_storage(tmp_path, postgres_url)  # Optuna's tables, made by their owner
    engine = sqlalchemy.create_engine(postgres_url, isolation_level="AUTOCOMMIT")
    with engine.connect() as connection:
        connection.execute(sqlalchemy.text("DROP ROLE IF EXISTS roto_weak"))
        connection.execute(sqlalchemy.text("CREATE ROLE roto_weak LOGIN PASSWORD 'Xq7/Zk9'"))
    engine.dispose()
    weak = postgres_url.replace("://roto@", f"://roto_weak:{LEFT}/{RIGHT}@")  # trust: any password does
    assert main(["sweep", "show", "--study", "s", "--storage", weak]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and LEFT not in err, err
    assert "roto_weak:***@" in err and "permission denied for table" in err and "the role needs SELECT" in err
    with engine.connect() as connection:
        connection.execute(sqlalchemy.text("GRANT SELECT ON ALL TABLES IN SCHEMA public TO roto_weak"))
    engine.dispose()
    storage = open_storage(tmp_path, weak)  # reading works now; writing does not
    with pytest.raises(DatabasePermissionDenied, match=r"roto_weak:\*\*\*@.*permission denied for table .*INSERT"):
        optuna.create_study(study_name="refused", storage=storage)

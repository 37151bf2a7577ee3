"""A throwaway PostgreSQL server for tests: its own data directory, port and superuser.

The server runs from the binaries of an installed PostgreSQL (Debian's ``postgresql`` package;
``.ci/run`` installs it), never from a cluster the system manages. PostgreSQL refuses to run as
root, so as root (tests in containers, CI) the server runs as an unprivileged user instead.
"""

from __future__ import annotations

import contextlib
import glob
import os
import pathlib
import pwd
import re
import shutil
import socket
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from typing import NamedTuple

SUPERUSER = "roto"
DATABASE = "roto_test"
DEBIAN_BIN_GLOB = "/usr/lib/postgresql/*/bin"
"""Debian installs the server binaries here, one folder per major version, and not on PATH."""
SERVER_USERS = ("postgres", "nobody")
"""Who runs the server when the tests run as root: the first of these that exists."""
START_TIMEOUT_S = 60


class Binaries(NamedTuple):
    """Paths of the PostgreSQL server programs."""

    initdb: pathlib.Path
    pg_ctl: pathlib.Path
    postgres: pathlib.Path


def find_binaries() -> Binaries | None:
    """The server programs on PATH, else in Debian's newest version folder; None when missing."""
    on_path = [shutil.which(name) for name in Binaries._fields]
    if all(on_path):
        return Binaries(*(pathlib.Path(path) for path in on_path))
    for folder in sorted(glob.glob(DEBIAN_BIN_GLOB), key=_version, reverse=True):
        paths = [pathlib.Path(folder, name) for name in Binaries._fields]
        if all(os.access(path, os.X_OK) for path in paths):
            return Binaries(*paths)
    return None


def _version(folder: str) -> tuple[int, ...]:
    """``/usr/lib/postgresql/9.6/bin`` -> (9, 6), so that 15 sorts after 9.6."""
    return tuple(int(part) for part in re.findall(r"\d+", pathlib.Path(folder).parent.name))


class Server(NamedTuple):
    """A running throwaway server: its URL, and a way to restart it (a fault to survive)."""

    url: str
    restart: Callable[[float], None]
    """``restart(down_s)``: stop the server (connections dropped), wait ``down_s`` s, start it again."""


@contextlib.contextmanager
def postgres_server(binaries: Binaries | None = None) -> Iterator[str]:
    """Run a fresh server on 127.0.0.1 and yield a SQLAlchemy URL of an empty database on it
    (``running_server``'s URL)."""
    with running_server(binaries) as server:
        yield server.url


@contextlib.contextmanager
def running_server(binaries: Binaries | None = None) -> Iterator[Server]:
    """Run a fresh server on 127.0.0.1 with an empty database; yield its URL and its restart.

    The server is stopped and its files deleted on exit, also when the body raised. Raises
    RuntimeError when the binaries are missing or the server does not start.
    """
    binaries = binaries or find_binaries()
    if binaries is None:
        raise RuntimeError(
            f"PostgreSQL's server (initdb, pg_ctl, postgres) is neither on PATH nor in {DEBIAN_BIN_GLOB}"
        )
    user = _server_user()
    root = _make_root(user)
    data, log = root / "data", root / "server.log"

    def restart(down_s: float) -> None:
        _run([binaries.pg_ctl, "stop", "-D", data, "-m", "fast", "-w"], user, root)
        time.sleep(down_s)
        _start(binaries, data, log, user, root)

    try:
        _run([binaries.initdb, "-D", data, "-U", SUPERUSER, "--auth=trust", "--no-locale", "-E", "UTF8"], user, root)
        port = free_port()
        _configure(data, port, socket_dir=root)
        try:
            _start(binaries, data, log, user, root)
            _create_database(port, log)
            yield Server(f"postgresql+psycopg2://{SUPERUSER}@127.0.0.1:{port}/{DATABASE}", restart)
        finally:
            # immediate: the data is thrown away, so skip the shutdown checkpoint; -w returns once
            # the server has exited. It fails harmlessly when the server never started.
            _run([binaries.pg_ctl, "stop", "-D", data, "-m", "immediate", "-w"], user, root, check=False)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now (the OS picks it)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _server_user() -> str | None:
    """The user to run the server as when we are root (PostgreSQL refuses root), else None."""
    if os.geteuid() != 0:
        return None
    for name in SERVER_USERS:
        with contextlib.suppress(KeyError):
            return pwd.getpwnam(name).pw_name
    raise RuntimeError(f"running as root, and none of the users {SERVER_USERS} exists to run PostgreSQL as")


def _make_root(user: str | None) -> pathlib.Path:
    """A new private folder for the server's files, owned by ``user`` when given.

    In /tmp rather than under $TMPDIR or pytest's tmp_path: those may sit in folders only root can
    enter (pytest's /tmp/pytest-of-root is 0700), which the server's user could not reach.
    """
    root = pathlib.Path(tempfile.mkdtemp(prefix="roto-pg-", dir="/tmp" if user else None))
    if user:
        entry = pwd.getpwnam(user)
        os.chown(root, entry.pw_uid, entry.pw_gid)
    return root


def _run(
    args: list[str | int | os.PathLike[str]], user: str | None, cwd: pathlib.Path, check: bool = True
) -> subprocess.CompletedProcess[str]:
    """Run a PostgreSQL program, as ``user`` when given; on failure raise with its output.

    ``cwd`` is a folder ``user`` can enter: initdb warns when it cannot return to the current one.
    """
    command = [str(arg) for arg in args]
    if user:
        command = ["runuser", "-u", user, "--", *command]
    result = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=START_TIMEOUT_S * 2)
    if check and result.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed ({result.returncode}):\n{result.stdout}{result.stderr}")
    return result


def _configure(data: pathlib.Path, port: int, socket_dir: pathlib.Path) -> None:
    """Listen on ``port`` of 127.0.0.1 only, with the unix socket in our folder (not the system's
    /var/run/postgresql), and skip flushing to disk: the data is thrown away."""
    settings = {
        "listen_addresses": "127.0.0.1",
        "port": port,
        "unix_socket_directories": str(socket_dir).replace("'", "''"),
        "fsync": "off",
        "synchronous_commit": "off",
        "full_page_writes": "off",
    }
    # appended, so these win over initdb's defaults; appending keeps the file's owner (the server's user)
    with open(data / "postgresql.conf", "a") as conf:
        conf.writelines(f"{name} = '{value}'\n" for name, value in settings.items())


def _start(binaries: Binaries, data: pathlib.Path, log: pathlib.Path, user: str | None, cwd: pathlib.Path) -> None:
    """Start the server and wait until it accepts connections; on failure raise with its log."""
    command = [binaries.pg_ctl, "start", "-D", data, "-l", log, "-p", binaries.postgres, "-w", "-t", START_TIMEOUT_S]
    try:
        _run(command, user, cwd)
    except RuntimeError as error:
        raise RuntimeError(f"{error}\n{_log_tail(log)}") from None


def _create_database(port: int, log: pathlib.Path) -> None:
    """Create the tests' database over TCP, which also checks that the server listens there."""
    # imported here so that find_binaries works (and tests can skip) without the sweep extra
    import psycopg2

    try:
        connection = psycopg2.connect(host="127.0.0.1", port=port, user=SUPERUSER, dbname="postgres")
    except psycopg2.OperationalError as error:
        raise RuntimeError(
            f"cannot connect to the PostgreSQL server on port {port}: {error}\n{_log_tail(log)}"
        ) from None
    try:
        connection.autocommit = True  # CREATE DATABASE cannot run in a transaction
        with connection.cursor() as cursor:
            cursor.execute(f"CREATE DATABASE {DATABASE}")
    finally:
        connection.close()


def _log_tail(log: pathlib.Path, lines: int = 30) -> str:
    """The last lines of the server's log, for error messages."""
    try:
        text = log.read_text(errors="replace").splitlines()[-lines:]
    except OSError as error:
        return f"(no server log: {error})"
    return "server log (tail):\n" + "\n".join(text)

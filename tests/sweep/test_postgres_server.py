import contextlib
import socket
import urllib.parse

import pytest

from tests.sweep.postgres_server import Binaries, postgres_server


def _accepts_connections(port: int) -> bool:
    """Whether something listens on ``port`` of 127.0.0.1."""
    try:
        socket.create_connection(("127.0.0.1", port), timeout=2).close()
    except OSError:
        return False
    return True


def test_url_reaches_a_writable_database(postgres_url: str):
    # imported here: without the sweep extra, the fixture skips (or fails) before this line
    import sqlalchemy as sa

    engine = sa.create_engine(postgres_url)
    try:
        with engine.begin() as connection:
            assert connection.execute(sa.text("SELECT 1")).scalar_one() == 1
            connection.execute(sa.text("CREATE TABLE server_check (id integer PRIMARY KEY, name text)"))
            connection.execute(sa.text("INSERT INTO server_check VALUES (1, 'roto')"))
        with engine.connect() as connection:  # a new connection: the row was committed
            assert connection.execute(sa.text("SELECT id, name FROM server_check")).all() == [(1, "roto")]
    finally:
        engine.dispose()


@pytest.mark.parametrize("body_raises", [False, True])
def test_server_stops_on_exit(postgres_binaries: Binaries, body_raises: bool):
    expected = pytest.raises(ValueError) if body_raises else contextlib.nullcontext()
    with expected, postgres_server(postgres_binaries) as url:
        port = urllib.parse.urlsplit(url).port
        assert _accepts_connections(port)
        if body_raises:
            raise ValueError("the test's body failed")
    assert not _accepts_connections(port)

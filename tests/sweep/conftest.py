import os
from collections.abc import Iterator

import pytest

from tests.conftest import require_extra
from tests.sweep.postgres_server import Binaries, find_binaries, postgres_server


@pytest.fixture(scope="session")
def postgres_binaries() -> Binaries:
    """PostgreSQL's server programs and the postgres extra's database driver, or a skip (a failure
    under ROTO_REQUIRE_EXTRAS, as in ``make test``)."""
    require_extra("sqlalchemy", "postgres")
    require_extra("psycopg2", "postgres")
    binaries = find_binaries()
    if binaries is None:
        missing = "PostgreSQL's server (initdb, pg_ctl, postgres) is not installed"
        if os.environ.get("ROTO_REQUIRE_EXTRAS"):
            pytest.fail(f"{missing} but ROTO_REQUIRE_EXTRAS is set: .ci/run installs it (apt-get install postgresql)")
        pytest.skip(f"{missing} (apt-get install postgresql, as .ci/run does)")
    return binaries


@pytest.fixture(scope="session")
def postgres_url(postgres_binaries: Binaries) -> Iterator[str]:
    """A SQLAlchemy URL of an empty database on a temporary server, shared by the session's tests
    (starting a server takes seconds); tests keep apart by naming their own tables or studies."""
    with postgres_server(postgres_binaries) as url:
        yield url

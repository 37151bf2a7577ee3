"""The CLI's error boundary: exit codes and which failures keep their traceback."""

from roto.cli_errors import error_exit


def test_runtime_failures_exit_1_and_unexpected_errors_keep_their_traceback():
    assert error_exit(MemoryError("out of memory")) == (1, "failed")
    assert error_exit(ConnectionResetError("peer")) == (1, "failed")
    assert error_exit(PermissionError("denied")) == (2, "error")
    assert error_exit(ValueError("bad")) == (2, "error")
    assert error_exit(ZeroDivisionError()) == (None, "")

"""The CLI's error boundary: exit codes and which failures keep their traceback."""

from roto.cli_errors import error_exit


def test_runtime_failures_exit_1_and_unexpected_errors_keep_their_traceback():
    assert error_exit(MemoryError("out of memory")) == (1, "failed")
    assert error_exit(ConnectionResetError("peer")) == (1, "failed")
    assert error_exit(PermissionError("denied")) == (2, "error")
    assert error_exit(ValueError("bad")) == (2, "error")
    assert error_exit(ZeroDivisionError()) == (None, "")


def test_ctrl_c_in_any_command_is_one_line_and_exit_130(monkeypatch, capsys):
    import pytest

    from roto import cli

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "_cmd_render", interrupted)  # the parser is built in main, with this
    assert cli.main(["render"]) == 130
    assert capsys.readouterr().err == "roto render: interrupted\n"
    with pytest.raises(KeyboardInterrupt):  # --debug keeps the traceback
        cli.main(["--debug", "render"])

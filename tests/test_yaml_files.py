"""Malformed or unreadable YAML files are one-line errors naming the file, on every command that reads one."""

import pytest

from roto.cli import main
from roto.envs.config import EnvConfig
from roto.olympiad.plan import load_plan
from roto.rl.config_files import load_agent_config, parse_override
from roto.rl.run_config import read_run_config
from roto.sweep.space import load_space
from roto.yaml_files import read_yaml

BROKEN = "ppo:\n  lr: [1e-4\n"


def test_a_syntax_error_names_the_file_line_and_problem(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text(BROKEN)
    with pytest.raises(ValueError, match=rf"agent config '{path}' is not valid YAML at line 3, column 1"):
        read_yaml(path, "agent config")


def test_a_directory_or_a_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match=rf"plan '{tmp_path}' cannot be read"):
        read_yaml(tmp_path, "plan")
    with pytest.raises(FileNotFoundError, match=r"plan .*missing.yaml' does not exist"):
        read_yaml(tmp_path / "missing.yaml", "plan")


def test_a_key_given_twice_is_refused_naming_both_lines(tmp_path, capsys):
    path = tmp_path / "twice.yaml"
    path.write_text("ppo:\n  lr: 1.0e-3\nnetwork:\n  encoder: [16]\nppo:\n  epochs: 2\n")
    with pytest.raises(
        ValueError, match=rf"agent config '{path}': key 'ppo' appears twice in one mapping, at lines 1 and 5"
    ):
        load_agent_config("bounce", str(path))
    run_dir = tmp_path / "run"
    assert main(["train", "--steps", "16", "--agent_cfg", str(path), "--run_dir", str(run_dir)]) == 2
    assert "key 'ppo' appears twice" in capsys.readouterr().err and not run_dir.exists()
    nested = tmp_path / "nested.yaml"
    nested.write_text("ppo: {lr: 1.0e-3, lr: 2.0e-3}\n")
    with pytest.raises(ValueError, match="key 'lr' appears twice in one mapping, at lines 1 and 1"):
        read_yaml(nested)


def test_a_merge_may_override_the_keys_it_brings_in(tmp_path):
    path = tmp_path / "merge.yaml"
    path.write_text("base: &base {lr: 1, epochs: 2}\nrun:\n  <<: *base\n  lr: 3\n")
    assert read_yaml(path)["run"] == {"lr": 3, "epochs": 2}


@pytest.mark.parametrize(
    ("load", "what"),
    [
        (lambda p: load_agent_config("bounce", p), "agent config"),
        (lambda p: load_plan(str(p)), "plan"),
        (lambda p: load_space(str(p), EnvConfig(task="bounce")), "search space"),
    ],
)
def test_every_loader_reports_a_malformed_file(tmp_path, load, what):
    path = tmp_path / "broken.yaml"
    path.write_text(BROKEN)
    with pytest.raises(ValueError, match=rf"{what} '{path}' is not valid YAML"):
        load(path)


def test_a_malformed_run_config_blocks_resume_with_the_file_named(tmp_path):
    (tmp_path / "config.yaml").write_text("train: [\n")
    with pytest.raises(ValueError, match=r"run config '.*config.yaml' is not valid YAML"):
        read_run_config(tmp_path)
    (tmp_path / "config.yaml").write_text("just: words\n")
    with pytest.raises(ValueError, match=r"is not a roto run config"):
        read_run_config(tmp_path)


def test_an_empty_agent_config_is_refused(tmp_path, capsys):
    path = tmp_path / "empty.yaml"
    path.write_text("# nothing here\n")
    assert main(["train", "--steps", "16", "--agent_cfg", str(path)]) == 2
    assert f"agent config '{path}' is empty" in capsys.readouterr().err


def test_the_cli_turns_a_malformed_agent_config_into_one_line(tmp_path, capsys):
    path = tmp_path / "broken.yaml"
    path.write_text(BROKEN)
    assert main(["train", "--steps", "16", "--agent_cfg", str(path)]) == 2
    err = capsys.readouterr().err
    assert "is not valid YAML" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_an_override_whose_value_is_not_yaml_is_a_clear_error():
    with pytest.raises(ValueError, match=r"override 'ppo.lr=\[1': the value '\[1' is not valid YAML"):
        parse_override("ppo.lr=[1")

from roto.cli import main
from roto.envs.config import EnvConfig
from roto.rl.config import AgentConfig
from roto.rl.config_help import attribute_section, config_keys, help_config
from roto.rl.overrides import FIXED_ENV_KEYS, env_override_keys


def test_every_agent_and_env_key_is_documented():
    rows = [*config_keys(AgentConfig), *config_keys(EnvConfig, "env.", skip=FIXED_ENV_KEYS)]
    undocumented = [key for key, _, doc in rows if not doc.strip()]
    assert not undocumented, f"config fields without a docstring: {undocumented}"
    keys = {key for key, _, _ in rows}
    assert {
        "ppo.rollouts",
        "run.keep_checkpoints",
        "ssl.forward_dynamics.tau",
        "env.aids.replayed_starts.share",
    } <= keys
    assert {key[4:].split(".")[0] for key in keys if key.startswith("env.")} == set(env_override_keys())


def test_help_config_prints_keys_defaults_and_meanings(capsys):
    import pytest

    with pytest.raises(SystemExit) as done:
        main(["train", "--help-config"])
    assert done.value.code == 0
    out = capsys.readouterr().out
    assert out == help_config() + "\n"
    rollouts = next(line for line in out.splitlines() if line.strip().startswith("ppo.rollouts "))
    assert " 16 " in rollouts and "Steps each env collects per update" in rollouts
    shown = {line.split()[0]: line.split()[1] for line in out.splitlines() if line.startswith("  env.aids.")}
    assert shown["env.aids.replayed_starts.bank"] == shown["env.aids.tolerance.start"] == "required"
    assert shown["env.aids.replayed_starts"] == "None" and shown["env.aids.replayed_starts.share"] == "0.25"


def test_attribute_sections_join_continuation_lines():
    doc = """A class.

    Attributes:
        alpha: the first
            value, continued.
        beta: the second.

    More text.
    """
    assert attribute_section(doc) == {"alpha": "the first value, continued.", "beta": "the second."}

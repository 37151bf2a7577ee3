import pytest

from roto.rl.config import AgentConfig, apply_overrides, from_dict, load_agent_config


@pytest.mark.parametrize("task", ["bounce", "baoding"])
def test_packaged_defaults_load(task):
    cfg = load_agent_config(task)
    assert isinstance(cfg, AgentConfig)
    assert cfg.network.encoder == ((512, 256) if task == "bounce" else (1024, 512, 256))


def test_baoding_defaults_follow_the_spec():
    p = load_agent_config("baoding").ppo
    assert (p.rollouts, p.epochs, p.minibatches, p.lam, p.lr, p.kl_adaptive) == (32, 8, 4, 0.95, 2.02e-4, True)


def test_unknown_key_names_its_dotted_path():
    with pytest.raises(ValueError, match=r"'ppo\.learning_rate'"):
        from_dict(AgentConfig, {"ppo": {"learning_rate": 1e-3}})
    with pytest.raises(ValueError, match=r"'optimiser'"):
        from_dict(AgentConfig, {"optimiser": {}})


def test_wrong_types_are_errors():
    with pytest.raises(ValueError, match=r"ppo\.epochs must be an integer"):
        from_dict(AgentConfig, {"ppo": {"epochs": 2.5}})
    with pytest.raises(ValueError, match=r"network\.encoder must be a list of integers"):
        from_dict(AgentConfig, {"network": {"encoder": "big"}})


def test_overrides_apply_and_validate():
    cfg = load_agent_config("bounce", overrides=["ppo.lr=1e-3", "network.encoder=[8, 8]"])
    assert cfg.ppo.lr == 1e-3 and cfg.network.encoder == (8, 8)
    with pytest.raises(ValueError, match=r"section\.key=value"):
        apply_overrides({}, ["ppo.lr"])
    with pytest.raises(ValueError, match=r"ppo\.rollouts must be >= 1"):
        load_agent_config("bounce", overrides=["ppo.rollouts=0"])


def test_missing_config_file_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_agent_config("bounce", tmp_path / "nope.yaml")

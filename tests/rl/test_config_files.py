import pytest

from roto.rl.config import AgentConfig, from_dict, to_dict
from roto.rl.config_files import apply_overrides, load_agent_config, packaged_configs


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


@pytest.mark.parametrize("name", sorted(packaged_configs()))
def test_every_packaged_config_loads_and_round_trips(name):
    cfg = load_agent_config("bounce", name)
    assert from_dict(AgentConfig, to_dict(cfg)) == cfg


def test_a_config_extends_another_and_lists_only_what_changes(tmp_path):
    base = tmp_path / "base.yaml"
    base.write_text("extends: bounce_privileged_critic\nppo: {epochs: 3, lr: 1.0e-4}\n")
    child = tmp_path / "child.yaml"
    child.write_text("extends: base.yaml\nppo: {lr: 2.0e-4}\nnetwork: {encoder: [64]}\n")
    config = load_agent_config("bounce", child)
    roto = load_agent_config("bounce")
    assert config.ppo.lr == 2.0e-4 and config.ppo.epochs == 3  # the child's, then the base's
    assert config.network.encoder == (64,) and config.network.critic == ("tactile", "proprio", "privileged")
    assert config.ppo.minibatches == roto.ppo.minibatches and config.run == roto.run  # the packaged root's


def test_every_packaged_diff_config_differs_from_its_base_only_where_it_says():
    import yaml

    from roto.rl.config_files import merge

    for name, path in packaged_configs().items():
        data = yaml.safe_load(path.read_text())
        if "extends" not in data:
            continue
        task = "baoding" if name.startswith("baoding") else "bounce"
        base = to_dict(load_agent_config(task, data.pop("extends")))
        aids = data.pop("training_aids", {})  # the env's, not the agent's (tests/rl/test_run_spec.py)
        assert to_dict(load_agent_config(task, name)) == to_dict(from_dict(AgentConfig, merge(base, data)))
        changed = {f"{s}.{k}" for s, section in data.items() for k in section} | set(aids)
        # a sweep's export whose best trial was the base it enqueued says so and changes nothing, as
        # does a config whose sweep's best did not hold up on other seeds ("keeps its base")
        header = path.read_text().splitlines()[0]
        found_base_best = header.startswith("# roto sweep export:") and "trial 0 (the best)" in header
        kept_base = "keeps its base" in header
        assert changed or found_base_best or kept_base, f"{name} extends its base without changing anything"


@pytest.mark.parametrize(
    ("files", "message"),
    [
        ({"a.yaml": "extends: a.yaml\n"}, "extend each other in a circle"),
        ({"a.yaml": "extends: b.yaml\n", "b.yaml": "extends: a.yaml\n"}, "extend each other in a circle"),
        ({"a.yaml": "extends: nosuch\n"}, "extends 'nosuch', which is neither a file beside it nor a packaged"),
    ],
)
def test_a_bad_extends_is_a_clear_error(tmp_path, files, message):
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    with pytest.raises(ValueError, match=message):
        load_agent_config("bounce", tmp_path / "a.yaml")

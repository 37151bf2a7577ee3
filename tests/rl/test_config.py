import pytest

from roto.rl.config import AgentConfig, apply_overrides, from_dict, load_agent_config, packaged_configs, to_dict


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


@pytest.mark.parametrize("name", sorted(packaged_configs()))
def test_every_packaged_config_loads_and_round_trips(name):
    cfg = load_agent_config("bounce", name)
    assert from_dict(AgentConfig, to_dict(cfg)) == cfg


def test_tuned_ssl_configs_follow_the_spec():
    fd = load_agent_config("bounce", "bounce_forward_dynamics")
    assert (fd.ppo.rollouts, fd.ppo.epochs, fd.ppo.minibatches) == (16, 10, 8)
    assert (fd.ssl.forward_dynamics.weight, fd.ssl.forward_dynamics.lr, fd.ssl.forward_dynamics.seq_length) == (
        0.0021, 1.5e-5, 8)  # fmt: skip
    memory = load_agent_config("baoding", "baoding_forward_dynamics_memory").ssl.forward_dynamics_memory
    assert (memory.weight, memory.lr, memory.seq_length, memory.capacity) == (0.025, 2.5e-4, 2, 0)
    recon = load_agent_config("baoding", "baoding_tactile_reconstruction").ssl.tactile_reconstruction
    assert (recon.weight, recon.epoch_ratio, recon.targets) == (0.0031, 0.75, ("tactile",))
    assert load_agent_config("bounce").ssl.enabled() == {}


def test_ssl_section_has_strict_keys_and_checked_values():
    with pytest.raises(
        ValueError, match=r"unknown config key 'ssl.contrastive'; valid keys here: \['forward_dynamics'"
    ):
        from_dict(AgentConfig, {"ssl": {"contrastive": {}}})
    with pytest.raises(ValueError, match=r"unknown config key 'ssl.forward_dynamics.horizon'.*'seq_length'"):
        from_dict(AgentConfig, {"ssl": {"forward_dynamics": {"horizon": 3}}})
    with pytest.raises(ValueError, match=r"ssl.forward_dynamics.seq_length must be >= 2"):
        load_agent_config("bounce", overrides=["ssl.forward_dynamics={seq_length: 1}"])
    with pytest.raises(ValueError, match=r"ssl.tactile_reconstruction.epoch_ratio must be in \(0, 1\]"):
        load_agent_config("bounce", overrides=["ssl.tactile_reconstruction={epoch_ratio: 0}"])
    with pytest.raises(ValueError, match=r"ssl.full_reconstruction.targets: unknown observation group 'audio'"):
        load_agent_config("bounce", overrides=["ssl.full_reconstruction={targets: [audio]}"])
    cfg = load_agent_config("bounce", overrides=["ssl.forward_dynamics={}", "ssl.forward_dynamics.weight=0.5"])
    assert list(cfg.ssl.enabled()) == ["forward_dynamics"] and cfg.ssl.forward_dynamics.weight == 0.5


def test_aux_epochs_follow_roto_rule():
    from roto.rl.ssl import aux_epochs

    assert [aux_epochs(10, r) for r in (0.25, 0.5, 1.0, 0.01)] == [2, 5, 10, 1]
    assert aux_epochs(7, 0.75) == 5


def test_max_log_std_bounds_the_policy_std():
    import math

    import torch

    from roto.rl.build import build_model

    agent = load_agent_config("bounce", overrides=["network.max_log_std=0.0", "network.encoder=[8]"])
    model = build_model({"tactile": 4, "proprio": 8}, 3, agent, "blind")
    with torch.no_grad():
        model.log_std.fill_(1.5)  # as a growing entropy bonus would push it
    _, log_std, _, _ = model({"tactile": torch.zeros(2, 4), "proprio": torch.zeros(2, 8)})
    assert torch.equal(log_std, torch.zeros(3)) and math.isclose(float(model.clamped_log_std().detach().exp()[0]), 1.0)
    roto_default = build_model({"tactile": 4, "proprio": 8}, 3, load_agent_config("bounce"), "blind")
    assert roto_default.max_log_std == 2.0
    with pytest.raises(ValueError, match=r"network.max_log_std must be above -20.0, got -30"):
        build_model(
            {"tactile": 4, "proprio": 8}, 3, load_agent_config("bounce", overrides=["network.max_log_std=-30"]), "blind"
        )


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

    from roto.rl.config import merge

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


def test_roto_bounce_numbers_live_in_the_config_classes_and_baoding_is_a_diff():
    import yaml

    assert load_agent_config("bounce") == AgentConfig()
    shipped = packaged_configs()
    bounce = yaml.safe_load(shipped["bounce"].read_text())
    assert bounce == {"network": {}}  # names the defaults, repeats no number
    baoding = yaml.safe_load(shipped["baoding"].read_text())
    assert baoding["extends"] == "bounce" and "gamma" not in baoding["ppo"]  # only what differs


def test_bounce_gpu_is_the_agent_of_the_recorded_gpu_run():
    """roto/configs/bounce_gpu.yaml must train exactly as the H100 run its comment reports."""
    import pathlib

    import yaml

    run_config = pathlib.Path(__file__).parents[2] / (
        "benchmarks/results/gpu_h100_2026-11-26/train_bounce_shadow_8192_gpu_tf32_seed1/config.yaml"
    )
    recorded = yaml.safe_load(run_config.read_text())["agent"]  # keys added since then take their defaults
    assert load_agent_config("bounce", "bounce_gpu") == from_dict(AgentConfig, recorded)

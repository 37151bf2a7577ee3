import pytest

from roto.rl.config import AgentConfig, from_dict
from roto.rl.config_files import load_agent_config, packaged_configs


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


@pytest.mark.parametrize(
    ("section", "message"),
    [
        ({"network": {"encoder": [256, 0]}}, r"network.encoder must list layer widths >= 1, got \[256, 0\]"),
        ({"network": {"value_head": [-3]}}, r"network.value_head must list layer widths >= 1, got \[-3\]"),
        ({"network": {"init_log_std": float("nan")}}, r"network.init_log_std must be a finite number, got nan"),
        ({"ppo": {"lr": float("inf")}}, r"ppo.lr must be a finite number, got inf"),
        ({"ppo": {"ratio_clip": -0.1}}, r"ppo.ratio_clip must be >= 0, got -0.1"),
        ({"ppo": {"max_grad_norm": -1.0}}, r"ppo.max_grad_norm must be > 0, got -1.0"),  # would flip the gradients
        ({"ppo": {"kl_target": 0.0}}, r"ppo.kl_target must be > 0, got 0.0"),
        ({"ppo": {"value_coef": -1.0}}, r"ppo.value_coef must be >= 0, got -1.0"),
        ({"ppo": {"kl_factor": 1.0}}, r"ppo.kl_factor must be > 1 \(the adaptive rate's step\), got 1.0"),
        ({"ppo": {"lr_min": 0.1, "lr_max": 0.01}}, r"ppo.lr_min must be <= ppo.lr_max, got 0.1 > 0.01"),
    ],
)
def test_values_no_run_can_use_are_refused_naming_the_key(section, message):
    with pytest.raises(ValueError, match=message):
        from_dict(AgentConfig, section).validate()


def test_every_packaged_config_passes_the_checks():
    for name in packaged_configs():
        task = "bounce" if name.startswith("bounce") else "baoding"
        assert load_agent_config(task, name).validate()


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

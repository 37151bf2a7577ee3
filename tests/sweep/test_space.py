import optuna
import pytest

from roto.envs.config import EnvConfig
from roto.sweep.space import as_overrides, load_space, packaged_spaces

ENV = EnvConfig(task="bounce", num_envs=8)


def write_space(tmp_path, text):
    path = tmp_path / "space.yaml"
    path.write_text(text)
    return str(path)


def test_packaged_spaces_are_roto2_roto1_cpu_quickstart_and_baoding_cpu_and_load_for_their_configs():
    assert set(packaged_spaces()) == {"roto2", "roto1", "cpu_quickstart", "cpu_quickstart_noise", "baoding_cpu"}
    plain = load_space("roto2", ENV, "bounce")
    assert [p.key for p in plain.parameters] == [
        "ppo.rollouts", "ppo.minibatches", "ppo.epochs", "ppo.lr", "ppo.entropy_coef", "ppo.value_coef",
        "ppo.ratio_clip",
    ]  # fmt: skip
    assert len(load_space("roto1", ENV, "bounce").parameters) == 9
    quick = load_space("cpu_quickstart", ENV, "bounce_cpu_quickstart")
    assert [p.key for p in quick.parameters] == [p.key for p in plain.parameters]  # the same seven, narrower
    orca = EnvConfig(task="bounce", robot="orca", num_envs=8)
    noise = load_space("cpu_quickstart_noise", orca, "bounce_cpu_quickstart")
    assert noise.parameters[:7] == quick.parameters and noise.parameters[7].key == "network.init_log_std"
    bank = "shadow_preswap"
    baoding = load_space("baoding_cpu", EnvConfig(task="baoding", num_envs=8), "baoding_cpu_v1",
                         [f"env.aids.replayed_starts.bank={bank}", "env.aids.replayed_starts.share=0.25"])  # fmt: skip
    assert [p.key for p in baoding.parameters] == [
        *(p.key for p in plain.parameters), "network.max_log_std", "env.aids.replayed_starts.share"
    ]  # fmt: skip
    with pytest.raises(
        ValueError, match=r"aids.replayed_starts needs \['bank'\], got \{'share': 0\.1\}"
    ):  # the bank is the study's to set
        load_space("baoding_cpu", EnvConfig(task="baoding", num_envs=8), "baoding_cpu_v1")
    for recipe_cfg in ("baoding_cpu", "experiments/baoding_configs/baoding_cpu_shadow.yaml"):  # each its own bank
        recipe = load_space("baoding_cpu", EnvConfig(task="baoding", num_envs=8), recipe_cfg)
        assert [p.key for p in recipe.parameters] == [p.key for p in baoding.parameters]


def test_ssl_parameters_expand_over_the_base_configs_auxiliary_losses():
    fd = {p.key for p in load_space("roto2", ENV, "bounce_forward_dynamics").parameters}
    assert {"ssl.forward_dynamics.lr", "ssl.forward_dynamics.weight", "ssl.forward_dynamics.seq_length"} <= fd
    recon = {p.key for p in load_space("roto1", ENV, "bounce_tactile_reconstruction").parameters}
    assert "ssl.tactile_reconstruction.epoch_ratio" in recon
    assert not any(key.endswith("seq_length") for key in recon)  # reconstruction has no sequences


def test_suggested_values_stay_in_their_distributions_and_become_overrides():
    space = load_space("roto2", ENV)
    trial = optuna.create_study().ask()
    params = space.suggest(trial)
    assert params["ppo.rollouts"] in (16, 32, 64) and 4 <= params["ppo.epochs"] <= 10
    assert 1e-5 <= params["ppo.lr"] <= 5e-4
    assert f"ppo.epochs={params['ppo.epochs']}" in as_overrides(params)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("parameters:\n  ppo.lrr: {type: float, low: 1.0e-5, high: 1.0e-3}", r"'ppo.lrr'.*valid keys here: \["),
        ("parameters:\n  env.gravity: {type: float, low: 1.0, high: 2.0}", r"'gravity'; valid env keys: \["),
        ("parameters:\n  ppo.lr: {type: float, low: 1.0e-3, high: 1.0e-5}", r"'ppo.lr': low > high"),
        ("parameters:\n  ppo.lr: {type: gaussian, low: 0.1, high: 0.2}", r"unknown distribution 'gaussian'.*"
         r"valid types: \['categorical', 'float', 'int'\]"),
        ("parameters:\n  ppo.lr: {type: float, low: 0.0, high: 0.1, log: true}", r"'ppo.lr'.*log scale needs low > 0"),
        ("parameters:\n  ppo.epochs: {type: int, low: 1.5, high: 4}", r"'ppo.epochs': low must be an integer"),
        ("parameters:\n  ppo.rollouts: {type: categorical, choices: [16, 0]}", r"'ppo.rollouts' = 0.*>= 1"),
        ("parameters:\n  ppo.lr: {type: float, low: 0.1, high: 0.2, q: 2}", r"unknown keys \['q'\]"),
        ("ssl_parameters:\n  wieght: {type: float, low: 0.1, high: 0.2}", r"unknown ssl parameter 'wieght'.*'weight'"),
        ("params:\n  ppo.lr: {type: float, low: 0.1, high: 0.2}", r"unknown sections \['params'\]"),
        ("", r"no parameter to search \(its 'parameters' are empty\); a trial would train the base config"),
        ("parameters: {}\nssl_parameters:\n  weight: {type: float, low: 0.1, high: 0.2}",
         r"its ssl_parameters tune none of the base config's auxiliary losses"),
    ],
)  # fmt: skip
def test_a_bad_space_is_rejected_naming_the_key_and_the_valid_choices(tmp_path, text, message):
    with pytest.raises(ValueError, match=message):
        load_space(write_space(tmp_path, text), ENV)


def test_an_unknown_space_name_lists_the_packaged_ones():
    names = r"\['baoding_cpu', 'cpu_quickstart', 'cpu_quickstart_noise', 'roto1', 'roto2'\]"
    with pytest.raises(FileNotFoundError, match=r"'roto3'.*" + names):
        load_space("roto3", ENV)


def test_cli_rejects_a_bad_space_before_any_trial_runs(tmp_path, capsys):
    from roto.cli import main

    space = write_space(tmp_path, "parameters:\n  ppo.lr: {type: float, low: 1.0, high: 0.5}")
    code = main(["sweep", "--study", "bad", "--root", str(tmp_path), "--space", space, "--trials", "2"])
    assert code == 2
    assert "'ppo.lr': low > high" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()  # no study was created, no trial ran


def test_an_exported_config_names_a_file_base_relative_to_itself(tmp_path):
    from roto.sweep.report import changed_keys, extends_name

    (tmp_path / "configs").mkdir()
    base = tmp_path / "configs" / "mine.yaml"
    base.write_text("extends: bounce\n")
    assert extends_name("bounce_cpu", tmp_path / "out" / "x.yaml") == "bounce_cpu"
    assert extends_name(str(base), tmp_path / "out" / "x.yaml") == "../configs/mine.yaml"
    assert changed_keys({"ppo": {"lr": 1, "gamma": 2}, "ssl": {}}, {"ppo": {"lr": 3, "gamma": 2}, "ssl": {}}) == {
        "ppo": {"lr": 3}
    }


def test_a_parameter_contains_exactly_the_values_its_distribution_can_draw():
    from roto.sweep.space import Parameter

    epochs = Parameter("ppo.epochs", "int", low=2, high=8, step=2)
    assert epochs.contains(4) and not epochs.contains(3) and not epochs.contains(10) and not epochs.contains(True)
    lr = Parameter("ppo.lr", "float", low=1e-5, high=1e-3, log=True)
    assert lr.contains(2.59e-4) and not lr.contains(2e-3)
    rollouts = Parameter("ppo.rollouts", "categorical", choices=(16, 32))
    assert rollouts.contains(32) and not rollouts.contains(64)

import pathlib

import pytest

from roto.rl.config_files import packaged_configs
from roto.rl.run_spec import build_run_spec
from roto.rl.runner import Trainer
from roto.robots import ROBOTS
from tests.conftest import SHADOW_BANK
from tests.rl.toy_env import ToyEnv

TINY = ["network.encoder=[16]", "network.policy_head=[8]", "network.value_head=[8]", "ppo.rollouts=4",
        "ppo.epochs=1", "ppo.minibatches=1", "run.num_eval_envs=2"]  # fmt: skip


def test_env_overrides_set_any_env_field_and_win_over_flags():
    overrides = ["env.touch=force", "env.seed=7", "env.backend=warp", "ppo.lr=1e-3"]
    spec = build_run_spec("bounce", "allegro", "state", "bounce_cpu", overrides, 64, num_envs=8, seed=1, touch="binary")
    assert (spec.env.robot, spec.env.obs_mode, spec.env.num_envs) == ("allegro", "state", 8)
    assert (spec.env.touch, spec.env.seed, spec.env.backend) == ("force", 7, "warp")
    assert spec.agent.ppo.lr == 1e-3 and spec.agent.ppo.epochs == 5 and spec.steps == 64


def test_a_configs_training_aids_set_the_training_envs_per_hand_and_an_override_wins(tmp_path):
    base, banks = tmp_path / "aided.yaml", pathlib.Path(SHADOW_BANK).parent  # the reference controller's banks
    base.write_text(
        "extends: baoding_cpu_v1\ntraining_aids:\n"
        f"  replayed_starts: {{bank: '{banks}/{{robot}}_preswap.npz', share: 0.25}}\n"
        "  tolerance: {start: 0.025}\n"
    )
    (tmp_path / "more.yaml").write_text("extends: aided.yaml\ntraining_aids:\n  replayed_starts: {share: 0.5}\n")
    overrides = ["env.aids.tolerance.start=0.02", "env.aids.round_swaps={}"]
    spec = build_run_spec("Baoding", "Allegro", "blind", str(tmp_path / "more.yaml"), overrides)
    assert (spec.env.task, spec.env.robot) == ("baoding", "allegro")  # names in any case, as roto.make takes them
    replayed = spec.env.aids.replayed_starts
    assert (replayed.bank, replayed.share) == (f"{banks}/allegro_preswap.npz", 0.5)  # through extends
    assert (
        spec.env.aids.tolerance.start == 0.02 and spec.agent.ppo.epochs == 4
    )  # the override wins; baoding_cpu_v1's agent
    assert spec.env.aids.round_swaps.min_turn == 0.25  # switched on by an override, at its default
    off = build_run_spec("baoding", "allegro", "blind", str(tmp_path / "more.yaml"), ["env.aids.tolerance=null"])
    assert off.env.aids.tolerance is None and off.env.aids.replayed_starts == replayed
    assert spec.env.without_training_aids() == build_run_spec("baoding", "allegro", "blind", "baoding_cpu_v1").env
    base.write_text("extends: baoding_cpu_v1\ntraining_aids:\n  num_envs: 4096\n")
    with pytest.raises(ValueError, match=r"unknown training aid aids.num_envs; valid aids: \['replayed_starts'"):
        build_run_spec("baoding", "allegro", "blind", str(base))
    base.write_text("extends: baoding_cpu_v1\ntraining_aids: [replayed_starts]\n")
    with pytest.raises(ValueError, match=r"training_aids must be a mapping of aids to their settings, got \[.replayed"):
        build_run_spec("baoding", "allegro", "blind", str(base))
    base.write_text("extends: baoding_cpu_v1\ntraining_aids:\n  replay_share: 0.5\n")  # the flat form of format 1
    with pytest.raises(ValueError, match=r"\['replay_share'\] are now set per aid, as \['replayed_starts.share'\]"):
        build_run_spec("baoding", "allegro", "blind", str(base))
    with pytest.raises(ValueError, match=r"env.replay_share=0.5.*set per aid now: env.aids.replayed_starts.share="):
        build_run_spec("baoding", "allegro", "blind", "baoding_cpu", ["env.replay_share=0.5"])


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (["env.task=baoding"], "unknown env key 'task'"),
        (["env.backend=abacus"], "abacus"),
        (["ppo.nosuch=1"], "unknown config key 'ppo.nosuch'"),
        (  # the section's name as an agent config writes it
            ["training_aids.turn_shaping.per_turn=10"],
            r"config's training_aids are the envs' aids; on the command line: env.aids.turn_shaping.per_turn=\.\.\.",
        ),
    ],
)
def test_a_bad_spec_is_refused_before_anything_exists(overrides, message, tmp_path):
    with pytest.raises(ValueError, match=message):
        build_run_spec("bounce", overrides=overrides)


def test_open_creates_then_continues_a_run_and_refuses_other_settings(tmp_path):
    spec = build_run_spec("bounce", obs="proprio", overrides=TINY, steps=32, num_envs=4)
    run = tmp_path / "run"
    first = Trainer.open(run, spec, tensorboard=False, env_factory=ToyEnv)
    assert first.update == 0
    first.train(progress=False)
    longer = build_run_spec("bounce", obs="proprio", overrides=TINY, steps=64, num_envs=4)
    again = Trainer.open(run, longer, tensorboard=False, env_factory=ToyEnv)  # same run, a larger budget
    assert again.update == 2 and again.spec.steps == 64
    again.train(progress=False)
    other = build_run_spec("bounce", obs="proprio", overrides=[*TINY, "ppo.lr=1e-3"], steps=64, num_envs=4)
    with pytest.raises(ValueError, match=r"exists with other settings .*'agent.ppo.lr': \(0.001, 0.000259\)"):
        Trainer.open(run, other, tensorboard=False, env_factory=ToyEnv)
    with pytest.raises(FileNotFoundError):
        Trainer.open(tmp_path / "nothing_here", tensorboard=False, env_factory=ToyEnv)


def test_a_run_that_died_before_its_first_checkpoint_starts_over_without_its_old_records(tmp_path):
    from roto.rl.evaluation import read_evaluations

    spec = build_run_spec("bounce", obs="proprio", overrides=[*TINY, "run.eval_every=1"], steps=32, num_envs=4)
    run = tmp_path / "run"
    Trainer.open(run, spec, tensorboard=False, env_factory=ToyEnv).train(progress=False)
    first = read_evaluations(run)
    for checkpoint in (run / "checkpoints").glob("*.pt"):
        checkpoint.unlink()  # as if it had died after its evaluations, before any checkpoint
    again = Trainer.open(run, spec, tensorboard=False, env_factory=ToyEnv)
    assert again.update == 0 and read_evaluations(run) == []
    again.train(progress=False)
    assert [r["update"] for r in read_evaluations(run)] == [1, 2]
    assert [r["return_mean"] for r in read_evaluations(run)] == [r["return_mean"] for r in first]  # same seed


def hand_of(config_name: str) -> str:
    """The hand a packaged config is named for (``baoding_cpu_orca`` -> orca), else the Shadow."""
    named = [robot for robot in ROBOTS if config_name.endswith(f"_{robot}") or f"_{robot}_" in config_name]
    return max(named, key=len) if named else "shadow"


@pytest.mark.parametrize("name", sorted(packaged_configs()))
def test_every_packaged_config_trains_one_update_from_any_directory(name, tmp_path, monkeypatch):
    """Everything a packaged config needs (its base configs, its banks) ships with roto: it trains
    from a folder that is not the repository."""
    monkeypatch.chdir(tmp_path)
    task = "baoding" if name.startswith("baoding") else "bounce"
    tiny = ["env.episode_steps=8", "ppo.rollouts=8", "run.num_eval_envs=1", "run.eval_every=100"]
    tiny += ["ppo.cuda_graph=false"] if name.endswith("_gpu") else []  # its update graph needs a CUDA device
    spec = build_run_spec(task, hand_of(name), "blind", name, tiny, 2 * 8, num_envs=2)
    with Trainer.open(tmp_path / "run", spec, tensorboard=False) as trainer:
        trainer.train(progress=False)
        assert trainer.update == 1

"""Smoke tests of ``roto train / eval / play`` (tiny budgets) and their error messages."""

import json
import struct

import imageio.v2 as imageio
import pytest
import yaml

from roto.artifact_formats import FORMATS
from roto.cli import main
from roto.rl.checkpoints import load_checkpoint
from roto.rl.run_dir import load_policy
from roto.rl.runner import Trainer

TINY = [
    "network.encoder=[16]",
    "network.policy_head=[8]",
    "network.value_head=[8]",
    "ppo.rollouts=4",
    "ppo.epochs=1",
    "ppo.minibatches=1",
    "run.num_eval_envs=2",
    "run.checkpoint_every=1",
]


def read_event_tags(events_dir):
    """Scalar tags in TensorBoard event files (TFRecord framing: length, crc, payload, crc)."""
    from tensorboardX.proto import event_pb2

    tags = set()
    for path in events_dir.glob("events.out.tfevents.*"):
        data = path.read_bytes()
        offset = 0
        while offset < len(data):
            (length,) = struct.unpack("<Q", data[offset : offset + 8])
            payload = data[offset + 12 : offset + 12 + length]
            offset += 12 + length + 4
            event = event_pb2.Event.FromString(payload)
            tags.update(v.tag for v in event.summary.value)
    return tags


@pytest.fixture(scope="module")
def trained_run(tmp_path_factory):
    run_dir = tmp_path_factory.mktemp("cli") / "run"
    args = ["train", "--num_envs", "4", "--steps", "48", "--run_dir", str(run_dir), "--no_progress", *TINY]
    assert main([*args, "env.action_smoothing=0.9"]) == 0  # an env override beside the agent's
    return run_dir


def test_train_writes_config_checkpoints_csv_and_events(trained_run, capsys):
    config = yaml.safe_load((trained_run / "config.yaml").read_text())
    assert config["env"]["action_smoothing"] == 0.9 and config["agent"]["ppo"]["rollouts"] == 4
    latest = load_checkpoint(trained_run / "checkpoints" / "latest.pt")
    assert config["format"] == FORMATS["run config"] and latest["format"] == FORMATS["checkpoint"]
    assert config["steps"] == latest["spec"]["steps"] and latest["spec"]["env"] == config["env"]
    ckpts = trained_run / "checkpoints"
    assert (ckpts / "latest.pt").is_file() and (ckpts / "agent_3.pt").is_file()
    csv_text = (trained_run / "scalars.csv").read_text()
    for tag in ("ppo/approx_kl", "ppo/clip_fraction", "ppo/explained_variance", "loss/entropy", "ppo/action_std",
                "ppo/lr", "loss/surrogate", "loss/value", "loss/total", "perf/simulation_s", "perf/inference_s",
                "perf/update_s", "perf/eval_s", "eval/return_mean"):  # fmt: skip
        assert f",{tag}," in csv_text
    tags = read_event_tags(trained_run / "tensorboard")
    assert {"ppo/approx_kl", "perf/steps_per_s"} <= tags


def test_resume_extends_a_run(trained_run, capsys):
    assert main(["train", "--resume", str(trained_run), "--steps", "64", "--no_progress"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["updates"] == 4 and summary["env_steps"] == 64


def test_eval_prints_and_writes_json(trained_run, tmp_path, capsys):
    out = tmp_path / "eval.json"
    ckpt = trained_run / "checkpoints" / "latest.pt"
    assert main(["eval", "--checkpoint", str(ckpt), "--episodes", "3", "--out", str(out)]) == 0
    printed = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    written = json.loads(out.read_text())
    assert printed["episodes"] == 3 and len(written["per_episode"]["bounces"]) == 3
    assert {"return_mean", "return_std", "bounces_mean", "length_mean"} <= printed.keys()
    cell = {"task": "bounce", "task_version": 0, "robot": "shadow", "obs": "blind", "touch": "binary"}
    assert {key: written[key] for key in cell} == cell and written["seed"] == 1_000_000
    assert written["train_seed"] == yaml.safe_load((trained_run / "config.yaml").read_text())["env"]["seed"]


def test_eval_reads_a_gpu_trained_policy_only_checkpoint_as_gpu_suite_writes_it(trained_run, tmp_path, capsys):
    import torch

    from roto.rl.run_dir import POLICY_KEYS

    full = trained_run / "checkpoints" / "latest.pt"
    state = torch.load(full, weights_only=True)
    policy = tmp_path / "policy_latest.pt"
    gpu = {k: state[k] for k in POLICY_KEYS}  # as benchmarks/gpu_suite.sh keeps it: no env state
    gpu["spec"]["env"].update(backend="warp", device="cuda")  # trained on a GPU; evaluated on this CPU
    torch.save(gpu, policy)
    results = []
    for checkpoint in (full, policy):
        capsys.readouterr()
        assert main(["eval", "--checkpoint", str(checkpoint), "--episodes", "2"]) == 0
        results.append(json.loads(capsys.readouterr().out.strip().splitlines()[-1]))
    assert results[0]["return_mean"] == results[1]["return_mean"]


def test_play_writes_an_mp4_with_one_frame_per_step(trained_run, tmp_path):
    video = tmp_path / "play.mp4"
    ckpt = trained_run / "checkpoints" / "latest.pt"
    assert main(["play", "--checkpoint", str(ckpt), "--video", str(video), "--video_length", "20"]) == 0
    frames = [frame for frame in imageio.get_reader(str(video), format="FFMPEG")]  # len() of the reader is inf
    assert len(frames) == 20 and frames[0].shape == (480, 640, 3)
    assert frames[0].std() > 5  # an actual picture, not a blank frame


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["train", "--task", "juggle", "--steps", "16"], "unknown task 'juggle'"),
        (["train", "--steps", "16", "ppo.learning_rate=1"], "unknown config key 'ppo.learning_rate'"),
        (["train", "--obs", "xray", "--steps", "16"], "xray"),
        (["eval", "--checkpoint", "missing/latest.pt"], "does not exist"),
        (["play", "--checkpoint", "missing/latest.pt"], "does not exist"),
        (["train", "--resume", "missing_run"], "not a roto run directory"),
        (["train", "--steps", "-5"], "step budget must be an integer >= 1, got -5"),
        (["train", "--steps", "0"], "got 0"),
        (
            ["train", "--steps", "16", "ssl.jepa={}"],
            "unknown config key 'ssl.jepa'; valid keys here: ['forward_dynamics'",
        ),
        (["train", "--steps", "16", "--agent_cfg", "bounce_fd"], "packaged config: ['baoding'"),
        (["train", "--steps", "16", "network.actor=[privileged]"], "valid groups for this obs mode"),
        (["train", "--steps", "16", "env.task=baoding"], "unknown env key 'task'; valid env keys: ['num_envs'"),
        (["train", "--steps", "16", "env.num_envs=0"], "num_envs must be an integer >= 1, got 0"),
        (["eval", "--checkpoint", "config.yaml"], "'config.yaml' is not a roto checkpoint"),
    ],
)
def test_bad_input_is_a_clear_error(args, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "config.yaml").write_text("not: a checkpoint\n")
    assert main(args) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "runs").exists()  # nothing written for a rejected command


def test_train_records_evaluations_and_draws_the_learning_curve(trained_run, tmp_path):
    from roto.eval.plots import plot_learning_curve
    from roto.rl.evaluation import read_evaluations

    records = read_evaluations(trained_run)
    # eval_every 25 with 3 updates: only the evaluation after the last update (then the resume's)
    assert [r["update"] for r in records][:1] == [3] and records[0]["env_steps"] == 48
    assert len(records[0]["per_episode"]["return"]) == 2  # run.num_eval_envs=2: one episode each
    assert records[0]["return_mean"] == sum(records[0]["per_episode"]["return"]) / 2
    out = plot_learning_curve(trained_run, tmp_path / "curve.png")
    assert out is not None and out.stat().st_size > 1000
    assert plot_learning_curve(tmp_path) is None  # no evaluations: no figure


def test_a_privileged_critic_run_evaluates_and_plays_with_its_blind_policy(tmp_path, capsys):
    run_dir = tmp_path / "priv"
    overrides = [*TINY, "network.critic=[tactile, proprio, privileged]", "ssl.forward_dynamics={seq_length: 2}"]
    assert (
        main(["train", "--num_envs", "4", "--steps", "16", "--run_dir", str(run_dir), "--no_progress", *overrides]) == 0
    )
    ckpt = run_dir / "checkpoints" / "best.pt"
    assert main(["eval", "--checkpoint", str(ckpt), "--episodes", "2", "--out", str(tmp_path / "e.json")]) == 0
    assert json.loads(capsys.readouterr().out.strip().splitlines()[-1])["episodes"] == 2
    assert main(["play", "--checkpoint", str(ckpt), "--video", str(tmp_path / "p.mp4"), "--video_length", "5"]) == 0


def test_a_force_touch_run_keeps_its_touch_through_eval(tmp_path, capsys):
    run_dir = tmp_path / "force"
    overrides = [*TINY, "ssl.tactile_reconstruction={weight: 0.1}"]
    args = ["train", "--num_envs", "4", "--steps", "16", "--touch", "force", "--run_dir", str(run_dir), "--no_progress"]
    assert main([*args, *overrides]) == 0
    assert "touch: force" in (run_dir / "config.yaml").read_text()
    ckpt = run_dir / "checkpoints" / "best.pt"
    assert main(["eval", "--checkpoint", str(ckpt), "--episodes", "2", "--out", str(tmp_path / "e.json")]) == 0
    _, settings = load_policy(ckpt)
    assert settings.env.touch == "force"
    trainer = Trainer.resume(run_dir)  # the learner the run trains with decodes force touch with MSE
    (reconstruction,) = trainer.alg.aux_losses
    assert not reconstruction.binary_tactile
    trainer.env.close()
    trainer.evaluator.env.close()


def test_train_refuses_an_existing_run_and_leaves_it_untouched(trained_run, capsys):
    before = {p: p.read_bytes() for p in [trained_run / "config.yaml", trained_run / "checkpoints" / "latest.pt"]}
    args = ["train", "--num_envs", "4", "--steps", "48", "--run_dir", str(trained_run), "--no_progress", *TINY]
    assert main(args) == 2
    assert f"already holds a run; continue it with --resume '{trained_run}'" in capsys.readouterr().err
    assert all(path.read_bytes() == data for path, data in before.items())


def test_ctrl_c_stops_training_with_the_resume_command_and_the_resume_finishes(tmp_path, monkeypatch, capsys):
    from roto.rl.ppo import PPO

    run_dir = tmp_path / "run"
    update = PPO.update
    calls = []

    def interrupted_second_update(self):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt  # what a second Ctrl-C raises mid-update (the first waits for the update's end)
        return update(self)

    monkeypatch.setattr(PPO, "update", interrupted_second_update)
    args = ["train", "--num_envs", "4", "--steps", "48", "--run_dir", str(run_dir), "--no_progress", *TINY]
    assert main(args) == 130
    err = capsys.readouterr().err
    assert f"interrupted at update 1 (at once); `roto train --resume {run_dir}` continues" in err
    assert "Traceback" not in err
    assert main(["train", "--resume", str(run_dir), "--no_progress"]) == 0  # the run is not left locked
    assert json.loads(capsys.readouterr().out.strip().splitlines()[-1])["updates"] == 3


def test_resume_refuses_overrides_and_a_budget_below_what_is_done(trained_run, capsys):
    config = (trained_run / "config.yaml").read_bytes()
    assert main(["train", "--resume", str(trained_run), "--no_progress", "ppo.lr=1e-3"]) == 2
    assert "the overrides ['ppo.lr=1e-3'] would be ignored" in capsys.readouterr().err
    assert main(["train", "--resume", str(trained_run), "--steps", "16", "--no_progress"]) == 2
    assert "step budget 16 is below the" in capsys.readouterr().err
    assert (trained_run / "config.yaml").read_bytes() == config  # a refused resume rewrites nothing


@pytest.mark.parametrize(
    "flags, named",
    [
        (
            "--num_envs 999 --seed 7 --robot allegro --task baoding --obs state --agent_cfg X --touch force",
            "--agent_cfg, --num_envs, --obs, --robot, --seed, --task, --touch would be ignored: drop them",
        ),
        ("--num-envs=4", "--num_envs would be ignored: drop it"),  # even at the run's own value
        (
            "--backend warp --device cuda --run_dir elsewhere ppo.lr=1e-3",
            "--backend, --device, --run_dir, the overrides ['ppo.lr=1e-3'] would be ignored",
        ),
    ],
)
def test_resume_refuses_every_flag_it_would_ignore_naming_them(trained_run, flags, named, capsys):
    config = (trained_run / "config.yaml").read_bytes()
    assert main(["train", "--resume", str(trained_run), "--no_progress", *flags.split()]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and named in err
    assert (trained_run / "config.yaml").read_bytes() == config


def test_resume_takes_its_budget_and_threads_from_the_command_line(trained_run, capsys):
    assert main(["train", "--resume", str(trained_run), "--steps", "80", "--threads", "2", "--no_progress"]) == 0
    assert json.loads(capsys.readouterr().out.strip().splitlines()[-1])["env_steps"] == 80


def relabelled(checkpoint, path, **env):
    """A copy of ``checkpoint`` at ``path`` whose env section says ``env``."""
    import torch

    state = torch.load(checkpoint, weights_only=True)
    state["spec"]["env"].update(env)
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.save(state, path)
    return str(path)


def test_eval_refuses_a_checkpoint_whose_labels_do_not_fit_its_weights(trained_run, tmp_path, capsys):
    latest = trained_run / "checkpoints" / "latest.pt"
    other_hand = relabelled(latest, tmp_path / "loose" / "allegro.pt", robot="allegro")
    assert main(["eval", "--checkpoint", other_hand, "--episodes", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bounce on allegro (blind), which the checkpoint names, gives" in err
    assert "its labels do not belong to its weights" in err and not (tmp_path / "loose" / "allegro.eval.json").exists()
    copied = tmp_path / "run"  # the same sizes (blind Bounce and Baoding read the same groups), inside its run
    (copied / "checkpoints").mkdir(parents=True)
    (copied / "config.yaml").write_bytes((trained_run / "config.yaml").read_bytes())
    other_task = relabelled(latest, copied / "checkpoints" / "best.pt", task="baoding")
    assert main(["eval", "--checkpoint", other_task, "--episodes", "2"]) == 2
    err = capsys.readouterr().err
    assert "names {'task': ('baoding', 'bounce')} (checkpoint, run), unlike its run's" in err and err.count("\n") == 1


def test_eval_under_a_file_fails_before_evaluating(trained_run, tmp_path, capsys):
    (tmp_path / "afile").write_text("")
    out = tmp_path / "afile" / "eval.json"
    assert main(["eval", "--checkpoint", str(trained_run / "checkpoints" / "latest.pt"), "--out", str(out)]) == 2
    assert f"'{tmp_path / 'afile'}' is not a directory (it is a file)" in capsys.readouterr().err


def test_zero_torch_threads_is_a_clear_error(capsys):
    assert main(["train", "--steps", "16", "--torch_threads", "0"]) == 2
    assert "--torch_threads must be an integer >= 1, got 0" in capsys.readouterr().err


def test_a_resume_after_a_crash_logs_each_update_once(tmp_path, capsys):
    """Updates logged after the checkpoint a run resumes from are run again: the CSV keeps one row
    per (update, tag), not two."""
    import csv
    import shutil

    run_dir = tmp_path / "run"
    assert main(["train", "--num_envs", "4", "--steps", "32", "--run_dir", str(run_dir), "--no_progress", *TINY]) == 0
    latest = run_dir / "checkpoints" / "latest.pt"
    shutil.copy(latest, tmp_path / "latest_at_2.pt")
    assert main(["train", "--resume", str(run_dir), "--steps", "48", "--no_progress"]) == 0
    shutil.copy(tmp_path / "latest_at_2.pt", latest)  # as if it crashed before update 3's checkpoint
    assert main(["train", "--resume", str(run_dir), "--steps", "64", "--no_progress"]) == 0
    with (run_dir / "scalars.csv").open(newline="") as f:
        rows = list(csv.reader(f))[1:]
    keys = [(row[1], row[2]) for row in rows]
    assert len(keys) == len(set(keys)) and {int(u) for u, _ in keys} == {1, 2, 3, 4}


@pytest.mark.parametrize("where", ["a_directory", "under_a_file"])
def test_play_to_a_path_that_cannot_be_a_video_is_one_line(trained_run, tmp_path, capsys, where):
    target = tmp_path
    if where == "under_a_file":
        (tmp_path / "file").write_text("x")
        target = tmp_path / "file" / "video.mp4"
    args = ["play", "--checkpoint", str(trained_run / "checkpoints" / "latest.pt"), "--video", str(target)]
    assert main([*args, "--video_length", "2"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("roto play: error:") and len(err.strip().splitlines()) == 1
    with pytest.raises(ValueError):  # --debug shows the traceback instead
        main(["--debug", *args, "--video_length", "2"])


def test_a_second_resume_of_a_run_in_use_is_refused_naming_the_process(trained_run, capsys):
    import os

    holder = Trainer.resume(trained_run, tensorboard=False)  # holds the run's lock until it trains or closes
    try:
        config = (trained_run / "config.yaml").read_bytes()
        assert main(["train", "--resume", str(trained_run), "--no_progress"]) == 2
        assert f"is in use by process {os.getpid()}" in capsys.readouterr().err
        assert (trained_run / "config.yaml").read_bytes() == config
    finally:
        holder._lock.close()
        holder.env.close()
        holder.evaluator.env.close()


def test_task_and_robot_names_in_any_case_train_into_the_canonical_run_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ["train", "--task", "Bounce", "--robot", "Shadow-Lite", "--num_envs", "2", "--steps", "8", "--no_progress"]
    assert main([*args, *TINY]) == 0
    (run,) = (tmp_path / "runs" / "bounce_shadow_lite_blind").iterdir()
    settings = yaml.safe_load((run / "config.yaml").read_text())["env"]
    assert (settings["task"], settings["robot"]) == ("bounce", "shadow_lite")

import pytest
import torch

from roto.envs.config import EnvConfig
from roto.rl.config_files import load_agent_config
from roto.rl.run_spec import RunSpec
from roto.rl.runner import Trainer
from tests.rl.toy_env import ToyEnv

TINY = [
    "network.encoder=[32, 32]",
    "network.policy_head=[16]",
    "network.value_head=[16]",
    "ppo.rollouts=4",
    "ppo.epochs=2",
    "ppo.minibatches=2",
    "run.num_eval_envs=2",
]


def tiny_trainer(tmp_path, name, updates, extra=(), **kwargs):
    env = EnvConfig(task="bounce", robot="shadow", num_envs=4, seed=3)
    agent = load_agent_config("bounce", overrides=[*TINY, *extra])
    return Trainer(RunSpec(env=env, agent=agent, steps=16 * updates), tmp_path / name, tensorboard=False, **kwargs)


def params(trainer):
    return {k: v.clone() for k, v in trainer.model.state_dict().items()}


def same_nested(a, b):
    """Exact equality of nested dicts / lists of tensors and plain values."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same_nested(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(same_nested(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, torch.Tensor):
        return torch.equal(a, b)
    return a == b


def test_same_seed_gives_identical_parameters(tmp_path):
    a = tiny_trainer(tmp_path, "a", 2)
    a.train(progress=False)
    b = tiny_trainer(tmp_path, "b", 2)
    b.train(progress=False)
    pa, pb = params(a), params(b)
    assert all(torch.equal(pa[k], pb[k]) for k in pa)
    # and training changed them
    fresh = params(tiny_trainer(tmp_path, "c", 2))
    assert not all(torch.equal(pa[k], fresh[k]) for k in pa)


def test_resume_continues_bit_identically(tmp_path):
    whole = tiny_trainer(tmp_path, "whole", 3)
    whole.train(progress=False)
    part = tiny_trainer(tmp_path, "part", 2)
    part.train(progress=False)
    resumed = Trainer.resume(tmp_path / "part", total_steps=16 * 3, tensorboard=False)
    assert resumed.update == 2
    resumed.train(progress=False)
    pw, pr = params(whole), params(resumed)
    assert all(torch.equal(pw[k], pr[k]) for k in pw)
    assert (
        resumed.alg.optimizer.state_dict()["state"][0]["step"] == whole.alg.optimizer.state_dict()["state"][0]["step"]
    )


def test_a_run_continued_on_other_threads_trains_as_the_uninterrupted_run(tmp_path):
    """C threads say how fast, not what: an Olympiad cell or a sweep trial may continue on fewer."""
    from roto.rl.run_dir import RunDir
    from roto.rl.run_spec import build_run_spec

    def spec(updates, threads):
        return build_run_spec("bounce", overrides=TINY, steps=16 * updates, num_envs=4, seed=3, threads=threads)

    whole = Trainer.open(tmp_path / "whole", spec(3, 2), tensorboard=False)
    whole.train(progress=False)
    Trainer.open(tmp_path / "part", spec(2, 2), tensorboard=False).train(progress=False)
    resumed = Trainer.open(tmp_path / "part", spec(3, 1), tensorboard=False)
    assert resumed.update == 2 and resumed.spec.env.threads == 1
    resumed.train(progress=False)
    pw, pr = params(whole), params(resumed)
    assert all(torch.equal(pw[k], pr[k]) for k in pw)
    assert RunDir(tmp_path / "part").config().env.threads == 1  # config.yaml says what it ran on last


AGENT_V2 = [
    "ssl.forward_dynamics_memory={seq_length: 2, capacity: 40}",
    "ssl.forward_dynamics={seq_length: 3, max_sequences: 6}",
    "ssl.full_reconstruction={epoch_ratio: 0.5}",
    "network.critic=[tactile, proprio, privileged]",
    "run.eval_every=1",
]


def test_resume_is_bit_identical_with_auxiliary_losses_and_a_privileged_critic(tmp_path):
    whole = tiny_trainer(tmp_path, "whole", 3, extra=AGENT_V2)
    whole.train(progress=False)
    tiny_trainer(tmp_path, "part", 2, extra=AGENT_V2).train(progress=False)
    resumed = Trainer.resume(tmp_path / "part", total_steps=16 * 3, tensorboard=False)
    resumed.train(progress=False)
    assert all(torch.equal(a, b) for a, b in zip(params(whole).values(), params(resumed).values(), strict=True))
    # EMA target encoders, heads, auxiliary optimisers and the sequence memory, exactly
    assert same_nested(whole.alg.state_dict(), resumed.alg.state_dict())
    memory_loss = next(aux for aux in resumed.alg.aux_losses if aux.name == "forward_dynamics_memory")
    assert memory_loss.memory.count == 40  # 12 + 16 + 16 windows (the last two rollouts with the tail)
    # the evaluations file holds each update once
    from roto.rl.evaluation import read_evaluations

    assert [r["update"] for r in read_evaluations(tmp_path / "part")] == [1, 2, 3]


def test_resume_forgets_evaluations_recorded_after_its_checkpoint(tmp_path):
    import shutil

    from roto.rl.evaluation import read_evaluations

    latest, aside = tmp_path / "run" / "checkpoints" / "latest.pt", tmp_path / "latest_at_2.pt"

    def keep_update_2(trainer, scalars):
        if trainer.update == 2:
            shutil.copy(latest, aside)

    trainer = tiny_trainer(tmp_path, "run", 3, extra=["run.eval_every=1", "run.checkpoint_every=2"])
    trainer.train(progress=False, on_update=keep_update_2)
    aside.replace(latest)
    resumed = Trainer.resume(tmp_path / "run", tensorboard=False)  # a crash after update 3's evaluation
    assert resumed.update == 2
    assert [r["update"] for r in read_evaluations(tmp_path / "run")] == [1, 2]
    resumed.train(progress=False)
    assert [r["update"] for r in read_evaluations(tmp_path / "run")] == [1, 2, 3]


def test_resume_without_a_checkpoint_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="roto run directory"):
        Trainer.resume(tmp_path)


def test_ppo_learns_the_toy_task(tmp_path):
    torch.set_num_threads(1)
    env = EnvConfig(task="bounce", obs_mode="proprio", num_envs=32, seed=0)
    agent = load_agent_config(
        "bounce",
        overrides=[
            "network.encoder=[64, 64]",
            "network.policy_head=[32]",
            "network.value_head=[32]",
            "ppo.rollouts=8",
            "ppo.epochs=4",
            "ppo.minibatches=4",
            "ppo.lr=3e-3",
            "ppo.entropy_coef=0.0",
            "ppo.gamma=0.5",
            "run.num_eval_envs=16",
        ],
    )
    spec = RunSpec(env=env, agent=agent, steps=32 * 8 * 60)
    trainer = Trainer(spec, tmp_path / "toy", tensorboard=False, env_factory=ToyEnv)
    last = trainer.train(progress=False)
    # random actions in [-1, 1] earn about 8 * (1 - 2/3) = 2.7 per 8-step episode; the optimum is 8
    assert last["eval/return_mean"] > 7.0, last


class CountingToyEnv(ToyEnv):
    """The toy env, counting its steps."""

    def __init__(self, config):
        super().__init__(config)
        self.steps = 0

    def step(self, action):
        self.steps += 1
        return super().step(action)


def test_best_checkpoint_holds_exactly_the_weights_of_the_best_evaluation(tmp_path):
    from roto.rl.checkpoints import load_checkpoint
    from roto.rl.evaluation import read_evaluations

    overrides = [*TINY, "ppo.rollouts=8", "ppo.lr=3e-3", "run.num_eval_envs=5", "run.eval_every=1"]
    env = EnvConfig(task="bounce", obs_mode="proprio", num_envs=8, seed=0)
    spec = RunSpec(env=env, agent=load_agent_config("bounce", overrides=overrides), steps=8 * 8 * 6)
    trainer = Trainer(spec, tmp_path / "toy", tensorboard=False, env_factory=CountingToyEnv)
    trainer.train(progress=False)
    records = read_evaluations(tmp_path / "toy")
    assert [r["update"] for r in records] == [1, 2, 3, 4, 5, 6]
    # evaluation envs step only while evaluating: one 8-step episode per evaluation
    assert trainer.evaluator.env.steps == 6 * 8
    best = max(records, key=lambda r: r["return_mean"])
    state = load_checkpoint(tmp_path / "toy" / "checkpoints" / "best.pt")
    assert state["update"] == best["update"]
    # the saved weights, evaluated again on the same starts, give the recorded figures exactly
    trainer.model.load_state_dict(state["model"])
    again = trainer.evaluator.evaluate(trainer.model, update=-1)
    assert again["per_episode"]["return"] == best["per_episode"]["return"]


def test_one_run_directory_serves_one_trainer_at_a_time(tmp_path):
    import os

    first = tiny_trainer(tmp_path, "run", 1)
    with pytest.raises(ValueError, match=rf"run '.*run' is in use by process {os.getpid()}"):
        tiny_trainer(tmp_path, "run", 1)
    first.train(progress=False)  # done: the run is free again
    resumed = Trainer.resume(tmp_path / "run", total_steps=32, tensorboard=False)
    resumed.train(progress=False)
    assert resumed.update == 2


@pytest.mark.parametrize(("keep", "numbered"), [(2, ["agent_4.pt", "agent_5.pt"]), (0, [])])
def test_only_the_newest_numbered_checkpoints_are_kept(tmp_path, keep, numbered):
    extra = ["run.checkpoint_every=1", "run.eval_every=1", f"run.keep_checkpoints={keep}"]
    tiny_trainer(tmp_path, "run", 5, extra=extra).train(progress=False)
    names = sorted(p.name for p in (tmp_path / "run" / "checkpoints").iterdir())
    assert names == sorted(["best.pt", "latest.pt", *numbered])


def test_a_negative_checkpoint_count_is_refused():
    with pytest.raises(ValueError, match=r"run\.keep_checkpoints must be >= 0, got -1"):
        load_agent_config("bounce", overrides=["run.keep_checkpoints=-1"])


def test_best_and_numbered_checkpoints_hold_the_policy_and_load_without_an_env(tmp_path):
    import roto.rl.run_dir as runner

    trainer = tiny_trainer(tmp_path, "run", 2, extra=["run.eval_every=1", "run.checkpoint_every=1"])
    trainer.train(progress=False)
    folder = tmp_path / "run" / "checkpoints"
    full = torch.load(folder / "latest.pt", weights_only=True)
    for name in ("best.pt", "agent_2.pt"):
        policy = torch.load(folder / name, weights_only=True)
        assert set(policy) == set(runner.POLICY_KEYS) and "ppo" in full and "env" in full
        assert (folder / name).stat().st_size < 0.5 * (folder / "latest.pt").stat().st_size

    assert not hasattr(runner, "RotoEnv")  # loading a policy never builds an env
    model, _ = runner.load_policy(folder / "agent_2.pt")
    trained = trainer.model.state_dict()
    assert all(torch.equal(value, trained[key]) for key, value in model.state_dict().items())


def test_resuming_from_a_policy_only_checkpoint_says_so(tmp_path):
    tiny_trainer(tmp_path, "run", 1, extra=["run.eval_every=1"]).train(progress=False)
    folder = tmp_path / "run" / "checkpoints"
    (folder / "best.pt").replace(folder / "latest.pt")
    with pytest.raises(ValueError, match="holds a policy only"):
        Trainer.resume(tmp_path / "run", tensorboard=False)


def test_a_run_directory_reads_back_what_training_wrote(tmp_path):
    from roto.rl.run_dir import RunDir

    trainer = tiny_trainer(tmp_path, "run", 2, extra=["run.eval_every=1"])
    trainer.train(progress=False)
    run = RunDir(tmp_path / "run")
    spec = run.config()
    assert spec == trainer.spec and spec.agent == trainer.agent
    assert [r["update"] for r in run.evaluations()] == [1, 2]
    steps, values = run.scalars()["eval/return_mean"]
    assert steps == [16, 32] and values == [r["return_mean"] for r in run.evaluations()]
    assert run.has_checkpoint() and run.has_checkpoint("best") and not run.has_checkpoint("agent_7")
    model, loaded = run.policy("latest")
    assert loaded == spec
    assert all(torch.equal(v, trainer.model.state_dict()[k]) for k, v in model.state_dict().items())


def test_a_worker_retrying_a_run_still_in_use_waits_until_it_is_free(tmp_path, capsys):
    import threading
    import time

    from roto.rl.run_lock import wait_until_free

    holder = tiny_trainer(tmp_path, "run", 1)  # holds the run's lock, as a worker declared dead but alive would
    waiter = threading.Thread(target=wait_until_free, args=(tmp_path / "run",))
    waiter.start()
    time.sleep(0.5)
    assert waiter.is_alive() and "is still used by process" in capsys.readouterr().out
    holder.train(progress=False)  # its training ends and lets the run go
    waiter.join(timeout=10)
    assert not waiter.is_alive()
    Trainer.resume(tmp_path / "run", total_steps=32, tensorboard=False).train(progress=False)  # free again


def test_ppo_projects_the_log_std_after_each_step_only_when_asked(tmp_path):
    """A large entropy bonus pushes the log std past its bound of 0: with ``network.project_log_std``
    every update leaves it at the bound, without it the parameter ends above (roto's clamp)."""
    bound = ["network.max_log_std=0.0", "ppo.entropy_coef=10.0"]
    clamped = tiny_trainer(tmp_path, "clamped", 2, bound)
    clamped.train(progress=False)
    assert bool((clamped.model.log_std > 0).all())
    projected = tiny_trainer(tmp_path, "projected", 2, [*bound, "network.project_log_std=true"])
    projected.train(progress=False)
    assert torch.equal(projected.model.log_std.detach(), torch.zeros_like(projected.model.log_std))


def test_a_signal_stops_training_after_the_update_with_its_checkpoint_and_the_resume_is_exact(tmp_path):
    """kill or Ctrl-C mid-run (here after update 2 of 4, checkpoints every 50): the run stops once
    update 2 is done and saved, and continuing it trains as the uninterrupted run."""
    import os
    import signal

    from roto.rl.checkpoints import load_checkpoint

    whole = tiny_trainer(tmp_path, "whole", 4)
    whole.train(progress=False)
    part = tiny_trainer(tmp_path, "part", 4)

    def kill_at_update_2(trainer, scalars):
        if trainer.update == 2:
            os.kill(os.getpid(), signal.SIGTERM)

    with pytest.raises(KeyboardInterrupt, match="SIGTERM: stopped after update 2"):
        part.train(progress=False, on_update=kill_at_update_2)
    assert part.agent.run.checkpoint_every > 4
    assert load_checkpoint(tmp_path / "part" / "checkpoints" / "latest.pt")["update"] == 2
    resumed = Trainer.resume(tmp_path / "part", tensorboard=False)
    assert resumed.update == 2
    resumed.train(progress=False)
    pw, pr = params(whole), params(resumed)
    assert all(torch.equal(pw[k], pr[k]) for k in pw)


def test_start_at_hold_starts_the_policy_at_the_hold_pose_and_draws_the_same_random_numbers(tmp_path):
    plain = tiny_trainer(tmp_path, "plain", 1)
    plain_rng = torch.get_rng_state()
    held = tiny_trainer(tmp_path, "held", 1, ["network.start_at_hold=true"])
    assert torch.equal(torch.get_rng_state(), plain_rng)  # the start drew no random number
    assert torch.equal(held.alg.generator.get_state(), plain.alg.generator.get_state())
    obs, _ = held.env.reset(seed=3)
    hold = held.env.hold_action()
    assert (held.model.act_deterministic(obs) - hold).abs().max() < 0.05
    assert (plain.model.act_deterministic(obs) - hold).abs().max() > 0.2
    same = [k for k in params(plain) if not k.startswith("policy_mean.")]
    assert all(torch.equal(params(plain)[k], params(held)[k]) for k in same)  # only the action layer differs

"""Training on a GPU: the rollout loop (policy, env step, buffer, episode statistics) never waits
for the device; the update and the evaluation read their results back once each."""

import pytest
import torch

from roto.envs.config import EnvConfig
from roto.rl.config_files import load_agent_config
from roto.rl.run_spec import RunSpec
from roto.rl.runner import Trainer

pytestmark = [pytest.mark.gpu, pytest.mark.skipif(not torch.cuda.is_available(), reason="needs an NVIDIA GPU")]


def test_gpu_rollouts_never_wait_for_the_device(tmp_path, monkeypatch):
    env = EnvConfig(task="bounce", robot="shadow", num_envs=2048, backend="warp", device="cuda", seed=0)
    agent = load_agent_config("bounce", overrides=["run.eval_every=2", "run.num_eval_envs_gpu=16"])
    spec = RunSpec(env=env, agent=agent, steps=3 * agent.ppo.rollouts * env.num_envs)
    trainer = Trainer(spec, tmp_path / "run", tensorboard=False)
    collect = trainer._collect_rollout
    rollouts = []

    def collect_without_waiting():
        torch.cuda.set_sync_debug_mode("error")
        try:
            result = collect()
        finally:
            torch.cuda.set_sync_debug_mode(0)
        rollouts.append(result)
        return result

    monkeypatch.setattr(trainer, "_collect_rollout", collect_without_waiting)
    summary = trainer.train(progress=False)
    assert len(rollouts) == 3 and trainer.env_steps == spec.steps
    assert all(torch.isfinite(p).all() for p in trainer.model.parameters())
    assert summary and (tmp_path / "run" / "evaluations.jsonl").is_file()

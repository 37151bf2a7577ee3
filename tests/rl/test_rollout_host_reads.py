"""The training rollout loop as a GPU runs it (the sync-free env step, the policy, the buffer, the
episode statistics), on Warp's CPU device: it reads nothing back from the device outside the
deliberate reads (the env's periodic checks, a training aid's state once per update). On a GPU,
tests/rl/test_training_gpu.py checks the same under CUDA's sync-debug mode."""

import pytest
import torch

from roto.envs.aids.event_recorder import RecordedEvents
from roto.envs.aids.tolerance import ToleranceAid
from roto.envs.config import EnvConfig
from roto.rl.config_files import load_agent_config
from roto.rl.run_spec import RunSpec
from roto.rl.runner import Trainer
from tests.conftest import BAODING_AIDS, require_warp

ARMED = {**BAODING_AIDS["aids"], "round_swaps": {"min_turn": 0.25, "first_paid": True, "after": 0.5}}
"""The recipe's aids with round swaps armed part way (an aid that follows the ended episodes)."""
NARROWING = {**BAODING_AIDS["aids"], "turn_shaping": {"per_turn": 20.0, "near": 1.0, "soft": True, "near_from": 3.0}}
"""The recipe's aids with turn shaping's near narrowing as the episodes turn the pair (another that follows them)."""


@pytest.mark.parametrize(
    "aids", [BAODING_AIDS["aids"], ARMED, NARROWING], ids=["aids", "armed_round_swaps", "narrowing_near"]
)
def test_rollouts_of_the_baoding_recipe_read_nothing_back(tmp_path, monkeypatch, host_reads, aids):
    require_warp()
    env = EnvConfig(
        task="baoding",
        robot="shadow",
        num_envs=4,
        backend="warp",
        device="cpu",
        seed=0,
        episode_steps=60,
        aids=aids,
    )
    agent = load_agent_config("baoding_cpu", overrides=["ppo.rollouts=8", "run.eval_every=100", "run.num_eval_envs=2"])
    spec = RunSpec(env=env, agent=agent, steps=3 * agent.ppo.rollouts * env.num_envs)
    trainer = Trainer(spec, tmp_path / "run", tensorboard=False)
    trainer.env.checks.go_sync_free(4)  # as on a GPU
    assert trainer.env.aid(RecordedEvents) is not None and trainer.env.aid(ToleranceAid) is not None
    collect, collected = trainer._collect_rollout, []

    def collect_watched():
        with host_reads:
            collected.append(collect())
        return collected[-1]

    monkeypatch.setattr(trainer, "_collect_rollout", collect_watched)
    trainer.train(progress=False)
    assert len(collected) == 3 and "train/success_radius" in collected[-1]
    assert host_reads.seen == [], f"host reads in the rollouts: {sorted(set(host_reads.seen))}"
    assert all(torch.isfinite(p).all() for p in trainer.model.parameters())

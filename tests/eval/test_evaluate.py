import torch

from roto.envs.config import EnvConfig
from roto.eval.evaluate import evaluate
from roto.rl.networks import ActorCritic
from roto.rl.runner import TrainSettings


class ThreadRecordingPolicy(ActorCritic):
    """An untrained actor-critic that records the torch thread count at every action."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.thread_counts: list[int] = []

    def act_deterministic(self, obs):
        self.thread_counts.append(torch.get_num_threads())
        return super().act_deterministic(obs)


def test_evaluate_runs_whole_episodes_on_one_torch_thread_and_restores_the_count():
    settings = TrainSettings(env=EnvConfig(task="bounce", robot="shadow", num_envs=2, threads=2))
    sizes = {"tactile": 68, "proprio": 320}
    policy = ThreadRecordingPolicy(
        sizes, 20, actor_groups=("tactile", "proprio"), encoder=(32,), policy_head=(16,), value_head=(16,)
    )
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        summary = evaluate(policy, settings, episodes=2)
        assert torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)
    assert summary["episodes"] == 2 and len(summary["per_episode"]["bounces"]) == 2
    assert policy.thread_counts and set(policy.thread_counts) == {1}

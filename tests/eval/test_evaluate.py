import torch

from roto.envs.config import EnvConfig
from roto.envs.episodes import first_episodes
from roto.envs.roto_env import RotoEnv
from roto.eval.evaluate import evaluate
from roto.rl.networks import ActorCritic
from roto.rl.run_spec import RunSpec


class ThreadRecordingPolicy(ActorCritic):
    """An untrained actor-critic that records the torch thread count at every action."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.thread_counts: list[int] = []

    def act_deterministic(self, obs):
        self.thread_counts.append(torch.get_num_threads())
        return super().act_deterministic(obs)


def test_evaluate_runs_whole_episodes_on_one_torch_thread_and_restores_the_count():
    settings = RunSpec(env=EnvConfig(task="bounce", robot="shadow", num_envs=2, threads=2))
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


BLIND_SHADOW_SIZES = {"tactile": 68, "proprio": 320}


def untrained_blind_policy() -> ActorCritic:
    torch.manual_seed(0)
    return ActorCritic(
        BLIND_SHADOW_SIZES, 20, actor_groups=("tactile", "proprio"), encoder=(32,), policy_head=(16,), value_head=(16,)
    )


def test_a_baoding_evaluation_adds_the_pair_turns_and_leaves_the_episodes_as_they_were():
    settings = RunSpec(env=EnvConfig(task="baoding", robot="shadow", num_envs=2))
    policy = untrained_blind_policy()
    summary = evaluate(policy, settings, episodes=2, seed=5)
    env = RotoEnv(settings.cpu_env_config(num_envs=2, seed=5))  # the same episodes without the ball state
    obs, _ = env.reset(seed=5)
    plain = first_episodes(env, policy.act_deterministic, obs)
    env.close()
    episodes = summary["per_episode"]
    assert episodes["return"] == plain["return"][:, 0].tolist() and episodes["swaps"] == plain["swaps"][:, 0].tolist()
    assert len(episodes["net_turns"]) == len(episodes["travelled_turns"]) == 2
    pairs = zip(episodes["net_turns"], episodes["travelled_turns"], strict=True)
    assert all(0.0 <= net <= travelled for net, travelled in pairs)
    assert sum(episodes["travelled_turns"]) > 0  # an untrained policy moves the balls some way
    backed = zip(episodes["rotations"], episodes["net_turns"], strict=True)
    assert episodes["round_rotations"] == [min(rotations, net) for rotations, net in backed]


def test_a_bounce_evaluation_has_no_path_metrics():
    settings = RunSpec(env=EnvConfig(task="bounce", robot="shadow", num_envs=1))
    summary = evaluate(untrained_blind_policy(), settings, episodes=1)
    assert set(summary["per_episode"]) == {"return", "length", "bounces"}

import torch

from roto.envs.ball_paths import with_ball_state
from roto.envs.config import EnvConfig
from roto.envs.observations import ball_positions, privileged_frame


def test_ball_positions_reads_the_newest_frame_of_a_stacked_privileged_group():
    frames = [torch.randn(3, 2, 3, dtype=torch.float64) for _ in range(4)]  # (B, n_ball, 3) per frame, oldest first
    stacked = torch.cat([privileged_frame(pos, torch.randn(3, 2, 3)) for pos in frames], dim=1)  # (B, 4 * 12)
    assert torch.equal(ball_positions(stacked, 2), frames[-1].to(torch.float32))


def test_the_ball_state_is_added_once_and_only_where_the_envs_lack_it():
    blind = EnvConfig(task="baoding", obs_mode="blind", extra_groups=("task",))
    assert with_ball_state(blind).extra_groups == ("task", "privileged")
    assert with_ball_state(with_ball_state(blind)) == with_ball_state(blind)
    state = EnvConfig(task="baoding", obs_mode="state")
    assert with_ball_state(state) is state

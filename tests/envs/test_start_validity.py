"""Episode starts are physically valid on every hand: no two parts of the hand interpenetrate, so
no touch bit is on while the ball is still in the air. Checked against MuJoCo's own contact list."""

import mujoco
import pytest
import torch

from roto.envs.start_pool import MAX_DRAW_ROUNDS, draw_valid_starts
from roto.robots import ROBOTS
from tests.conftest import make_env


def deepest_self_contact(model, qpos) -> float:
    """The slow reference: depth (m) of the deepest contact between two bodies of the hand."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    hand = {b for b in range(model.nbody) if model.body_rootid[b] == model.body_rootid[model.body(1).id]}
    depths = [
        -c.dist
        for c in data.contact[: data.ncon]
        if model.geom_bodyid[c.geom1] in hand and model.geom_bodyid[c.geom2] in hand
    ]
    return max([0.0, *depths])


@pytest.mark.parametrize("robot", sorted(ROBOTS))
@pytest.mark.parametrize("task", ["bounce", "baoding"])
def test_no_start_has_the_hand_pressed_into_itself(task, robot):
    env = make_env(task, robot=robot, num_envs=4, seed=3)
    starts = env._draw_starts(96)
    depths = [deepest_self_contact(env.model, q.numpy()) for q in starts["qpos"]]
    assert max(depths) == 0.0, f"deepest self-contact {1000 * max(depths):.2f} mm"
    if task == "bounce":  # the ball starts in the air, so nothing may touch (Baoding's balls rest in the hand)
        assert not starts["frame/tactile"].any(), "a touch bit is on at a start"
    assert len(starts["qpos"]) == 96
    env.close()


def test_the_raw_noise_does_press_fingers_together():
    """Without the rejection the Shadow's joint noise makes fingers interpenetrate (so the test above
    can fail): its candidates include self-contacts deeper than 2 mm."""
    env = make_env("bounce", robot="shadow", num_envs=4, seed=3)
    candidates = env._draw_candidates(64)
    assert float(candidates["penetration"].max()) > 0.002
    deepest = max(deepest_self_contact(env.model, q.numpy()) for q in candidates["qpos"])
    assert abs(deepest - float(candidates["penetration"].max())) < 1e-9  # the sensor reads the same depth
    env.close()


def counting_draw(bad_every: int):
    """Candidates numbered 0, 1, 2 ...; every ``bad_every``-th is pressed 1 mm into itself."""
    drawn = [0]

    def draw(k: int) -> dict[str, torch.Tensor]:
        x = torch.arange(drawn[0], drawn[0] + k)
        drawn[0] += k
        return {"x": x, "penetration": torch.where(x % bad_every == 0, 1e-3, 0.0)}

    return draw


def test_rejected_starts_are_replaced_in_draw_order():
    starts = draw_valid_starts(counting_draw(3), 7, "toy")
    assert starts["x"].tolist() == [1, 2, 4, 5, 7, 8, 10] and set(starts) == {"x"}


def test_a_hand_that_never_fits_is_a_clear_error():
    with pytest.raises(RuntimeError, match=rf"robot 'toy': 2 of 2 episode starts .* after {MAX_DRAW_ROUNDS} rounds"):
        draw_valid_starts(counting_draw(1), 2, "toy")

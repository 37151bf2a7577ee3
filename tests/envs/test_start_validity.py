"""Episode starts are physically valid on every hand: no two parts of the hand interpenetrate, and
no ball starts inside the hand or inside another ball, so no touch bit is on while the balls are
still in the air. Checked against MuJoCo's own contact list."""

import mujoco
import pytest
import torch

from roto.envs.start_pool import MAX_BALL_START_PENETRATION, MAX_DRAW_ROUNDS, draw_valid_starts
from roto.robots import ROBOTS
from roto.tasks.baoding import geometry_of
from tests.conftest import make_env, require_warp


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


def deepest_ball_contact(model, qpos) -> float:
    """The slow reference: depth (m) of the deepest contact of any ball, with the hand or a ball."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    balls = {b for b in range(model.nbody) if model.body(b).name.startswith("ball")}
    depths = [
        -c.dist
        for c in data.contact[: data.ncon]
        if model.geom_bodyid[c.geom1] in balls or model.geom_bodyid[c.geom2] in balls
    ]
    return max([0.0, *depths])


@pytest.mark.parametrize("robot", sorted(ROBOTS))
@pytest.mark.parametrize("task", ["bounce", "baoding"])
def test_no_start_has_the_hand_pressed_into_itself(task, robot):
    env = make_env(task, robot=robot, num_envs=4, seed=3)
    starts = env.starts.draw(96)
    depths = [deepest_self_contact(env.model, q.numpy()) for q in starts["qpos"]]
    assert max(depths) == 0.0, f"deepest self-contact {1000 * max(depths):.2f} mm"
    assert not starts["frame/tactile"].any(), "a touch bit is on at a start (the balls start in the air)"
    assert len(starts["qpos"]) == 96
    env.close()


@pytest.mark.parametrize("backend", ["cpu", "warp"])
@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_baoding_balls_start_clear_of_the_hand_and_of_each_other(robot, backend):
    """256 starts per hand and backend: no ball deeper than 1 mm in the hand or the other ball (MuJoCo's
    contact list at each start), and the first observation touches nothing."""
    if backend == "warp":
        require_warp()
    env = make_env("baoding", robot=robot, num_envs=4, seed=11, backend=backend)
    starts = env.starts.draw(256)
    depths = [deepest_ball_contact(env.model, q.numpy()) for q in starts["qpos"]]
    assert max(depths) <= MAX_BALL_START_PENETRATION, f"deepest ball contact {1000 * max(depths):.2f} mm"
    obs, _ = env.reset()
    assert not obs["tactile"].any()
    env.close()


def test_both_backends_draw_the_same_baoding_starts():
    require_warp()
    cpu = make_env("baoding", robot="shadow", num_envs=4, seed=5)
    warp = make_env("baoding", robot="shadow", num_envs=4, seed=5, backend="warp")
    cpu_starts, warp_starts = cpu.starts.draw(64), warp.starts.draw(64)
    assert torch.equal(cpu_starts["qpos"], warp_starts["qpos"])
    assert torch.equal(cpu.task_state.targets, warp.task_state.targets)
    cpu.close()
    warp.close()


def test_the_ball_check_rejects_a_ball_started_in_the_hand():
    """The clearance sensors read a ball placed inside the palm as deep as MuJoCo's contact list does."""
    env = make_env("baoding", robot="shadow", num_envs=4, seed=3)
    candidates = env.starts.candidates(8)
    assert float(candidates["ball_penetration"].max()) == 0.0  # dropped from above: clear
    qpos = candidates["qpos"].clone()
    rest = torch.tensor(geometry_of(env.robot).targets[0], dtype=torch.float64)  # where ball a rests on the hand
    qpos[:, env.layout.ball_qpos[0] : env.layout.ball_qpos[0] + 3] = rest - torch.tensor([0.0, 0.0, 0.015])
    sensors = env.backend.sensors_at(qpos, torch.zeros(8, env.model.nv, dtype=torch.float64), candidates["target"])
    found, dist = env.indices.ball_clearance.take(sensors.to(torch.float64)).unbind(-1)
    measured = torch.where(found > 0, -dist, 0.0).amax(dim=1)
    reference = torch.tensor([deepest_ball_contact(env.model, q.numpy()) for q in qpos], dtype=torch.float64)
    assert float(reference.min()) > 0.005  # 15 mm lower than where it rests: well inside the hand
    torch.testing.assert_close(measured, reference, atol=1e-9, rtol=0)
    env.close()


def test_the_raw_noise_does_press_fingers_together():
    """Without the rejection the Shadow's joint noise makes fingers interpenetrate (so the test above
    can fail): its candidates include self-contacts deeper than 2 mm."""
    env = make_env("bounce", robot="shadow", num_envs=4, seed=3)
    candidates = env.starts.candidates(64)
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
        bad = x % bad_every == 0
        return {"x": x, "penetration": torch.where(bad, 1e-3, 0.0), "ball_penetration": torch.zeros(k)}

    return draw


def test_rejected_starts_are_replaced_in_draw_order():
    starts = draw_valid_starts(counting_draw(3), 7, "toy")
    assert starts["x"].tolist() == [1, 2, 4, 5, 7, 8, 10] and set(starts) == {"x"}


def test_a_hand_that_never_fits_is_a_clear_error():
    with pytest.raises(RuntimeError, match=rf"robot 'toy': 2 of 2 episode starts .* after {MAX_DRAW_ROUNDS} rounds"):
        draw_valid_starts(counting_draw(1), 2, "toy")


def test_a_ball_deeper_than_1mm_is_rejected_and_one_within_it_kept():
    """Candidates 0, 1, 2 ...: the even ones have a ball 2 mm inside the hand, the odd ones 0.5 mm."""
    drawn = [0]

    def draw(k: int) -> dict[str, torch.Tensor]:
        x = torch.arange(drawn[0], drawn[0] + k)
        drawn[0] += k
        return {"x": x, "penetration": torch.zeros(k), "ball_penetration": torch.where(x % 2 == 0, 2e-3, 5e-4)}

    assert draw_valid_starts(draw, 3, "toy")["x"].tolist() == [1, 3, 5]

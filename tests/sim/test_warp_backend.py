"""The Warp backend on Warp's CPU device: parity with the CPU backend, isolation, capacity, errors.

The first test to build a Warp model compiles MuJoCo Warp's kernels (tens of seconds per hand on
2 cores); they are cached in ``.cache/warp`` (``roto.sim.mujoco_warp.warp_cache_dir``).
"""

import json
import math

import pytest
import torch

import roto
from roto.robots import ROBOTS, get_robot
from roto.sim.make_backend import make_backend
from roto.sim.scene import BallSpec, build_scene
from roto.tasks import TASKS
from roto.tasks.baoding import rest_after_drop
from tests.conftest import require_warp

QPOS_TOLERANCE = 1e-3
"""Largest |qpos_warp - qpos_cpu| (rad or m) allowed over PARITY_STEPS smooth control steps.
Measured: at most 2.2e-5 (Shadow Baoding), 2.7e-6 (Allegro Bounce) over 40 steps."""
PARITY_STEPS = 30

CI_PAIRS = [("bounce", "allegro"), ("baoding", "shadow")]
ALL_PAIRS = [(task, robot) for task in TASKS for robot in ROBOTS]
BOX_FINGERS = {"orca"}
"""Hands whose finger collision shapes are boxes. When neighbouring fingers press together, MuJoCo
Warp's box-box collider returns some contact points twice where MuJoCo C returns them once (same
position, same depth; seen on ORCA's proximal links), so finger-finger forces differ and the
trajectories part within a few steps. Their parity is checked holding the default pose, where no
finger presses on another (docs/backends.md)."""


@pytest.fixture(autouse=True)
def _warp_installed():
    require_warp()


def smooth_actions(steps: int, num_envs: int, num_actions: int) -> torch.Tensor:
    """(steps, B, n) slow sinusoids, a different phase per actuator and env (no chaotic flailing)."""
    t = torch.arange(steps, dtype=torch.float32)[:, None, None]
    phase = torch.arange(num_envs * num_actions, dtype=torch.float32).reshape(1, num_envs, num_actions)
    return 0.5 * torch.sin(t / 10.0 + phase)


def physics(env) -> torch.Tensor:
    return torch.from_numpy(env.backend.physics_state())


def assert_parity(task: str, robot: str, workload: str = "smooth") -> None:
    """CPU and Warp envs from the same seed and actions: ``smooth`` sinusoids or ``hold`` (default pose)."""
    cpu = roto.make(task, robot=robot, num_envs=3, seed=0)
    warp = roto.make(task, robot=robot, num_envs=3, seed=0, backend="warp")
    obs_cpu, _ = cpu.reset()
    obs_warp, _ = warp.reset()
    assert torch.equal(obs_cpu["tactile"], obs_warp["tactile"])
    assert torch.allclose(obs_cpu["proprio"], obs_warp["proprio"], atol=1e-5)
    nq = cpu.model.nq
    worst = 0.0
    actions = smooth_actions(PARITY_STEPS, 3, cpu.num_actions)
    if workload == "hold":
        actions = cpu.hold_action().expand_as(actions)
    for action in actions:
        obs_cpu, reward_cpu, term_cpu, trunc_cpu, _ = cpu.step(action)
        obs_warp, reward_warp, term_warp, trunc_warp, _ = warp.step(action)
        assert torch.equal(obs_cpu["tactile"], obs_warp["tactile"])
        assert torch.equal(term_cpu, term_warp) and torch.equal(trunc_cpu, trunc_warp)
        assert torch.allclose(reward_cpu, reward_warp, atol=1e-3)
        worst = max(worst, float((physics(cpu)[:, 1 : 1 + nq] - physics(warp)[:, 1 : 1 + nq]).abs().max()))
    assert worst < QPOS_TOLERANCE, worst
    warp.backend.check_overflow()
    cpu.close()
    warp.close()


@pytest.mark.parametrize(("task", "robot"), CI_PAIRS)
def test_warp_follows_the_cpu_backend(task, robot):
    assert_parity(task, robot)


@pytest.mark.slow
@pytest.mark.parametrize(("task", "robot"), ALL_PAIRS)
def test_warp_follows_the_cpu_backend_on_every_pair(task, robot):
    assert_parity(task, robot, "hold" if robot in BOX_FINGERS else "smooth")


def test_the_critics_groups_follow_the_cpu_backend():
    """What a Baoding critic reads beside the policy (the balls' state, the targets, latches and
    time left) is the same on both backends: the GPU recipe's critic sees what the CPU's saw."""
    groups = ("privileged", "task")
    cpu = roto.make("baoding", robot="shadow", num_envs=3, seed=0, extra_groups=groups)
    warp = roto.make("baoding", robot="shadow", num_envs=3, seed=0, backend="warp", extra_groups=groups)
    observations = [(cpu.reset()[0], warp.reset()[0])]
    for action in smooth_actions(PARITY_STEPS, 3, cpu.num_actions):
        observations.append((cpu.step(action)[0], warp.step(action)[0]))
    for obs_cpu, obs_warp in observations:
        assert torch.allclose(obs_cpu["privileged"], obs_warp["privileged"], atol=1e-3)
        assert torch.allclose(obs_cpu["task"], obs_warp["task"], atol=1e-6)
    assert observations[-1][0]["task"].abs().sum() > 0  # the group carries something to compare
    cpu.close()
    warp.close()


@pytest.mark.parametrize("name", ["allegro", "shadow"])
def test_ball_on_palm_gives_identical_bits_on_both_backends(name):
    robot = get_robot(name)
    model, layout = build_scene(robot, (BallSpec(name="ball", radius=0.02, mass=0.03),))
    qpos = torch.from_numpy(model.qpos0.copy())[None]
    qpos[0, layout.ball_qpos[0] : layout.ball_qpos[0] + 3] = torch.tensor([-0.01, 0.0, 0.03])  # above the palm
    ctrl = qpos[:, layout.act_qpos]
    backends = [
        make_backend("cpu", model, 1, substeps=4),
        make_backend("warp", model, 1, substeps=4, nconmax=32, njmax=128),
    ]
    force = layout.tactile_sensor + 1
    for backend in backends:
        backend.set_state(torch.tensor([0]), qpos, torch.zeros(1, model.nv))
    lit = 0
    for _ in range(20):
        bits = [(b.step(ctrl).sensordata[0, :, force] > 0.01).clone() for b in backends]
        assert torch.equal(bits[0], bits[1])
        lit += int(bits[0].sum())
    assert lit > 0  # the ball did land


def test_sensors_at_more_states_than_worlds_match_the_cpu_backend_and_change_no_world():
    envs = [roto.make("baoding", robot="allegro", num_envs=2, seed=0, backend=b) for b in ("cpu", "warp")]
    for env in envs:
        env.reset()
        for _ in range(5):
            env.step(env.hold_action().expand(2, -1))
    starts = envs[0].starts.draw(5)  # 5 states on 2 worlds: chunks of 2, 2 and 1 on Warp
    qpos, target = starts["qpos"], starts["target"]
    rest = torch.from_numpy(rest_after_drop(envs[0].robot))  # (2, 3) the balls landed in the hand
    for adr, ball in zip(envs[0].layout.ball_qpos, rest, strict=True):
        qpos[:, adr : adr + 3] = ball
    qvel = torch.zeros(5, envs[0].model.nv, dtype=torch.float64)
    before = physics(envs[1])
    sensors = [env.backend.sensors_at(qpos, qvel, target).to(torch.float64) for env in envs]
    assert torch.equal(physics(envs[1]), before)
    force = torch.from_numpy(envs[0].layout.tactile_sensor + 1)
    bits = [s[:, force] > envs[0].config.tactile_threshold for s in sensors]
    assert torch.equal(bits[0], bits[1]) and bits[0].any()  # the balls rest on the hand
    assert torch.equal(sensors[0], envs[0].backend.sensors_at(qpos, qvel, target))  # CPU: no world state used
    for env in envs:
        env.close()


def held_baoding_tactile(name: str, touch: str = "binary", steps: int = 20):
    """(CPU and Warp envs, their tactile observations over ``steps`` steps holding the Baoding balls)."""
    envs = [roto.make("baoding", robot=name, num_envs=1, backend=b, touch=touch) for b in ("cpu", "warp")]
    hold = envs[0].hold_action()
    tactile = []
    for env in envs:
        env.reset()
        tactile.append([env.step(hold)[0]["tactile"].clone() for _ in range(steps)])
    return envs, tactile


@pytest.mark.parametrize("name", ["allegro", "shadow"])
def test_held_baoding_balls_and_their_lift_read_the_same_on_both_backends(name):
    envs, tactile = held_baoding_tactile(name)
    idx = envs[0].indices
    hold = envs[0].hold_action()
    for step_cpu, step_warp in zip(*tactile, strict=True):
        assert torch.equal(step_cpu, step_warp)
    n_links = len(envs[0].robot.tactile_links)
    assert tactile[0][-1][0, -n_links:].sum() > 0
    for env in envs:  # lift both balls 30 cm: every bit clears within one step on both
        qpos = physics(env)[:, 1 : 1 + env.model.nq]
        qpos[0, idx.ball_pos.index[:, 2]] = 0.3
        env.backend.set_state(torch.tensor([0]), qpos, torch.zeros(1, env.model.nv))
        assert env.step(hold)[0]["tactile"][0, -n_links:].sum() == 0


FORCE_TOUCH_TOLERANCE = 1e-3
"""Largest |difference| of the force touch signal log(1 + |F| / F0) between the backends, i.e. 0.1 %
of the force. Measured: 4.6e-5 (Allegro), 1.1e-4 (Shadow) over 20 steps holding the Baoding balls."""


@pytest.mark.parametrize("name", ["allegro", "shadow"])
def test_force_touch_reads_the_same_forces_on_both_backends(name):
    envs, tactile = held_baoding_tactile(name, "force")
    for step_cpu, step_warp in zip(*tactile, strict=True):
        assert torch.equal(step_cpu > 0, step_warp > 0)  # the same links touched
        assert float((step_cpu - step_warp).abs().max()) < FORCE_TOUCH_TOLERANCE
    assert tactile[0][-1].max() > 1.0  # the balls press on the hand (more than 0.17 N on a link)
    for env in envs:
        env.close()


@pytest.mark.parametrize("name", ["allegro", "shadow"])
def test_taxels_light_the_same_on_both_backends(name):
    envs, tactile = held_baoding_tactile(name, "taxels")
    for step_cpu, step_warp in zip(*tactile, strict=True):
        assert torch.equal(step_cpu, step_warp)
    n_links = len(envs[0].robot.tactile_links)
    frame = envs[0].frame_sizes["tactile"]
    assert tactile[0][-1][0, -frame + n_links :].sum() > 0  # taxels under the balls are on
    for env in envs:
        env.close()


def test_same_seed_is_bit_identical_on_warp_cpu():
    runs = []
    for _ in range(2):
        env = roto.make("bounce", robot="allegro", num_envs=2, seed=3, backend="warp")
        obs, _ = env.reset()
        generator = torch.Generator().manual_seed(0)
        for _ in range(10):
            obs, reward, *_ = env.step(torch.rand((2, env.num_actions), generator=generator) * 2 - 1)
        runs.append((obs["proprio"], obs["tactile"], reward))
    for a, b in zip(*runs, strict=True):
        assert torch.equal(a, b)


def test_a_diverged_world_is_reset_and_the_others_are_untouched():
    envs = [roto.make("bounce", robot="allegro", num_envs=3, seed=1, backend="warp") for _ in range(2)]
    actions = smooth_actions(8, 3, envs[0].num_actions)
    for env in envs:
        env.reset()
        for action in actions[:4]:
            env.step(action)
    poisoned = envs[1]
    qpos = physics(poisoned)[1:2, 1 : 1 + poisoned.model.nq]
    qvel = torch.full((1, poisoned.model.nv), 1e12)  # beyond mjMAXVAL
    poisoned.backend.set_state(torch.tensor([1]), qpos, qvel)
    out_clean = envs[0].step(actions[4])
    out_poisoned = poisoned.step(actions[4])
    info = out_poisoned[4]
    assert info["nonfinite"].tolist() == [False, True, False]
    assert out_poisoned[2].tolist() == [False, True, False]  # terminated
    assert poisoned.nonfinite_resets == 1
    keep = torch.tensor([0, 2])
    for name in ("proprio", "tactile"):
        assert torch.allclose(out_clean[0][name][keep], out_poisoned[0][name][keep], atol=1e-6)
        assert torch.isfinite(out_poisoned[0][name]).all()
    for action in actions[5:]:  # the reset world steps on normally
        out_poisoned = poisoned.step(action)
        assert not out_poisoned[4]["nonfinite"].any()


def test_a_too_small_contact_capacity_is_an_error_not_silence():
    env = roto.make("baoding", robot="allegro", num_envs=2, backend="warp", nconmax=1, njmax=8)
    env.reset()
    with pytest.raises(RuntimeError, match=r"ran out of capacity for .*nconmax=1"):
        for _ in range(30):  # the dropped balls land within about 10 steps
            env.step(torch.zeros(2, env.num_actions))


def test_state_dict_round_trip_on_warp():
    env = roto.make("baoding", robot="allegro", num_envs=2, seed=4, backend="warp")
    env.reset()
    actions = smooth_actions(6, 2, env.num_actions)
    for action in actions[:3]:
        env.step(action)
    saved = env.state_dict()
    expected = [env.step(a)[0]["proprio"].clone() for a in actions[3:]]
    other = roto.make("baoding", robot="allegro", num_envs=2, seed=99, backend="warp")
    other.load_state_dict(saved)
    for action, want in zip(actions[3:], expected, strict=True):
        assert torch.equal(other.step(action)[0]["proprio"], want)


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has a GPU")
def test_cuda_without_a_gpu_is_a_clear_error():
    with pytest.raises(ValueError, match=r"device 'cuda' was asked for, but this machine has no CUDA GPU"):
        roto.make("bounce", backend="warp", device="cuda")


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"device": "tpu"}, r"device 'tpu' is not valid with backend 'warp'; valid: \['cpu', 'cuda'"),
        ({"nconmax": 0}, r"nconmax must be an integer >= 1 or None, got 0"),
    ],
)
def test_bad_warp_options_are_clear_errors(options, message):
    with pytest.raises(ValueError, match=message):
        roto.make("bounce", backend="warp", **options)


def test_bench_reports_the_ratio_to_bare_warp_steps():
    from roto.bench import run_bench

    result = run_bench("bounce", robot="allegro", num_envs=2, steps=4, warmup=1, backend="warp")
    assert result["backend"] == "warp" and result["device"] == "cpu"
    assert result["env_steps_per_s"] > 0 and result["raw_physics_steps_per_s"] > 0
    assert math.isfinite(result["efficiency"]) and result["efficiency"] > 0


def test_train_on_warp_then_evaluate_on_the_cpu_backend(tmp_path, capsys):
    from roto.cli import main
    from tests.test_cli_training import TINY

    run_dir = tmp_path / "run"
    args = ["train", "--backend", "warp", "--robot", "allegro", "--num_envs", "2", "--steps", "16"]
    assert main([*args, "--run_dir", str(run_dir), "--no_progress", *TINY]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["spec"]["env"]["backend"] == "warp" and summary["env_steps"] == 16
    assert "perf/simulation_s" in (run_dir / "scalars.csv").read_text()
    checkpoint = run_dir / "checkpoints" / "latest.pt"
    assert main(["eval", "--checkpoint", str(checkpoint), "--episodes", "1", "--out", str(tmp_path / "e.json")]) == 0

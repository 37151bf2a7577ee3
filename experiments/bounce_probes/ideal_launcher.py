"""How many bounces roto's contact model allows: Bounce's ball on a flat plate moved along a set path.

    python experiments/bounce_probes/ideal_launcher.py [--json FILE]

The plate stands in for a palm with no limits of its own: a 1000 kg box on a vertical slide whose
position and velocity are set before every physics step, under roto's Bounce ball (70 mm, 30 g,
friction 1), timestep (1/240 s), 4 substeps per control step, MuJoCo's default soft contact and the
touch threshold (0.01 N at any substep), counted by the task's own bounce rule
(``roto.tasks.bounce.bounce_counter``). Three questions, one table each:

1. a sine path (period P control steps, amplitude A): the best A for each P;
2. a free periodic path (four harmonics, a seeded hill climb from a sine) for P = 6 and 7: whether
   the contact itself allows a touch of one control step (100 bounces need a period of 6);
3. the Shadow's palm: its centre's fastest vertical speed when every actuator is driven bang-bang
   between its control limits, a half stroke of 1 to 6 control steps (what a palm can give a ball).
"""

from __future__ import annotations

import argparse
import json
import math

import mujoco
import numpy as np

from roto.envs.config import EnvConfig
from roto.eval.bounce_rhythm import rhythm
from roto.sim.scene import PHYSICS_DT
from roto.tasks.bounce import BALL, bounce_counter

SUBSTEPS = EnvConfig(task="bounce").substeps
THRESHOLD = EnvConfig(task="bounce").tactile_threshold
EPISODE_STEPS = 600
PLATE_XML = """
<mujoco>
  <option timestep="{dt}" integrator="implicitfast"/>
  <worldbody>
    <body name="plate">
      <joint name="lift" type="slide" axis="0 0 1"/>
      <geom type="box" size="0.1 0.1 0.01" pos="0 0 -0.01" mass="1000"/>
    </body>
    <body name="ball" pos="0 0 0.1">
      <freejoint/>
      <geom type="sphere" size="{radius}" mass="{mass}" friction="{friction}"/>
    </body>
  </worldbody>
</mujoco>
"""


def harmonic_path(period_steps: float, coef: np.ndarray):
    """t (s) -> (height, velocity) of a periodic path: sum over k of coef[2k]·sin + coef[2k+1]·cos
    of (k+1)·ω·t, ω = 2π / (period_steps control steps)."""
    omega = 2.0 * math.pi / (period_steps * SUBSTEPS * PHYSICS_DT)

    def path(t: float) -> tuple[float, float]:
        k = np.arange(1, len(coef) // 2 + 1) * omega
        sin, cos = np.sin(k * t), np.cos(k * t)
        return float(coef[0::2] @ sin + coef[1::2] @ cos), float(k @ (coef[0::2] * cos - coef[1::2] * sin))

    return path


def plate_episode(path) -> dict[str, float]:
    """One 600-step episode of the ball on the plate moved along ``path``: bounces by the task's rule,
    the mean touch and flight (control steps) of the counted bounces (``roto.eval.bounce_rhythm``)."""
    model = mujoco.MjModel.from_xml_string(
        PLATE_XML.format(dt=PHYSICS_DT, radius=BALL.radius, mass=BALL.mass, friction=BALL.friction)
    )
    data, force = mujoco.MjData(model), np.zeros(6)
    data.qpos[1:5] = [0.0, 0.0, path(0.0)[0] + BALL.radius + 0.005, 1.0]
    prev, waiting, free = np.array(False), np.array(False), np.array(0)
    contact, bounce, height = [], [], []
    for _ in range(EPISODE_STEPS):
        touched = False
        for _ in range(SUBSTEPS):
            data.qpos[0], data.qvel[0] = path(data.time)
            mujoco.mj_step(model, data)
            for i in range(data.ncon):
                mujoco.mj_contactForce(model, data, i, force)
                touched |= abs(force[0]) > THRESHOLD
        counted, waiting, free = bounce_counter(np.array(touched), prev, waiting, free)
        prev = np.array(touched)
        contact.append(touched)
        bounce.append(bool(counted))
        height.append(float(data.qpos[3]))
        if data.qpos[3] < path(data.time)[0] - 0.1:  # the ball fell off the plate
            break
    figures = rhythm(*(np.array(x)[:, None] for x in (contact, bounce, height)), np.array([len(contact)]))
    return {name: figures[name] for name in ("bounces", "touch_steps", "flight_steps")}


def path_limits(period_steps: float, coef: np.ndarray) -> dict[str, float]:
    """The path's stroke (cm), fastest speed (m/s) and largest acceleration (m/s²) over a period."""
    omega = 2.0 * math.pi / (period_steps * SUBSTEPS * PHYSICS_DT)
    t = np.linspace(0.0, 2.0 * math.pi / omega, 2000)[:, None]
    k = np.arange(1, len(coef) // 2 + 1)[None] * omega
    z = np.sin(k * t) @ coef[0::2] + np.cos(k * t) @ coef[1::2]
    v = (np.cos(k * t) * k) @ coef[0::2] - (np.sin(k * t) * k) @ coef[1::2]
    a = -(np.sin(k * t) * k**2) @ coef[0::2] - (np.cos(k * t) * k**2) @ coef[1::2]
    return {"stroke_cm": 100 * float(np.ptp(z)), "speed": float(np.abs(v).max()), "accel": float(np.abs(a).max())}


def best_sine(period_steps: float) -> dict[str, float]:
    """The sine amplitude (1 to 20 mm) that bounces most at this period, and its figures."""
    results = []
    for amplitude in np.linspace(0.001, 0.02, 39):
        coef = np.array([amplitude, 0.0])
        results.append({**plate_episode(harmonic_path(period_steps, coef)), **path_limits(period_steps, coef)})
    return max(results, key=lambda r: r["bounces"])


def free_search(period_steps: float, seed: int, iterations: int = 600) -> dict[str, float]:
    """A hill climb over four harmonics from a 10 mm sine: the most bounces found and the path's limits."""
    rng = np.random.default_rng(seed)
    coef = np.zeros(8)
    coef[0] = 0.01
    best = plate_episode(harmonic_path(period_steps, coef))
    for _ in range(iterations):
        candidate = coef + 0.005 * rng.standard_normal(8)
        result = plate_episode(harmonic_path(period_steps, candidate))
        if result["bounces"] >= best["bounces"]:
            best, coef = result, candidate
    return {**best, **path_limits(period_steps, coef)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", help="write every figure to this file")
    args = parser.parse_args()
    figures = {"sine": {}, "free": {}}
    print("| path | period (steps) | bounces | touch | flight | stroke (cm) | top speed (m/s) | top accel (m/s²) |")
    print("|---|---|---|---|---|---|---|---|")
    runs = [("sine", p, lambda p=p: best_sine(p)) for p in (6, 6.5, 7, 7.5, 8, 9)]
    runs += [("free", p, lambda p=p: free_search(p, seed=0)) for p in (6, 7)]
    for kind, period, make in runs:
        r = figures[kind][period] = make()
        print(
            f"| {kind} | {period} | {r['bounces']:.0f} | {r['touch_steps']:.2f} | {r['flight_steps']:.2f} | "
            f"{r['stroke_cm']:.1f} | {r['speed']:.2f} | {r['accel']:.0f} |",
            flush=True,
        )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(figures, f, indent=2)
            f.write("\n")


if __name__ == "__main__":
    main()

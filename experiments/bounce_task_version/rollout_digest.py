"""Did the Bounce task behave the same at two commits? Each commit's roto steps 16 envs of a
(hand, obs mode) for 1,500 steps under the scripted Bounce policy plus noise from a fixed
generator; every observation, reward, end flag and entry of ``info`` (episode records, reward
terms, final observations) is digested per key, the privileged group the recipes' critics read
included. The comparison prints, per pair, the keys whose digests differ and the keys only one
commit reports, with their largest magnitude (a term that is zero all along is a term added
later that the task does not pay).

    python experiments/bounce_task_version/rollout_digest.py OLD_CHECKOUT NEW_CHECKOUT shadow:blind ...
"""

import hashlib
import json
import os
import subprocess
import sys

STEPS = 1500
NUM_ENVS = 16
NOISE = 0.2  # uniform noise added to the scripted policy's actions, so the envs' paths differ


def flatten(name: str, value: object, out: dict) -> None:
    """Every tensor of a nested dict under its path (``obs/tactile``, ``info/episode/r``)."""
    import torch

    if isinstance(value, dict):
        for key in value:
            flatten(f"{name}/{key}", value[key], out)
    elif isinstance(value, torch.Tensor):
        out.setdefault(name, []).append(value.detach().cpu().to(torch.float64).reshape(-1).numpy())


def rollout_keys(robot: str, obs_mode: str) -> dict[str, list]:
    """{key: [SHA-256 prefix of its values over the rollout, largest magnitude]} for one pair."""
    import numpy as np
    import torch

    import roto
    from roto.scripted import ScriptedBounce

    # the scripted policy reads the privileged group and touch; the recipes' critics read the former
    extra = {"blind": ("privileged",), "proprio": ("privileged", "tactile"), "state": ()}[obs_mode]
    env = roto.make("bounce", robot=robot, num_envs=NUM_ENVS, obs_mode=obs_mode, seed=0, threads=1, extra_groups=extra)
    rng = np.random.default_rng(0)
    values: dict[str, list] = {}
    script = ScriptedBounce(env)  # it bounces the ball: random actions alone drop it at once
    obs, _ = env.reset(seed=0)
    flatten("reset", obs, values)
    for _ in range(STEPS):
        noise = torch.as_tensor(rng.uniform(-NOISE, NOISE, (NUM_ENVS, env.num_actions)), dtype=torch.float32)
        action = (script(obs).to(torch.float32) + noise).clamp(-1, 1)
        obs, reward, terminated, truncated, info = env.step(action)
        script.reset(terminated | truncated)
        step = {"obs": obs, "reward": reward, "terminated": terminated, "truncated": truncated, "info": info}
        flatten("", step, values)
    env.close()
    out = {}
    for key, parts in values.items():
        joined = np.concatenate(parts)
        out[key] = [hashlib.sha256(joined.tobytes()).hexdigest()[:16], float(np.abs(joined).max(initial=0.0))]
    return out


def run_at(checkout: str, pairs: list[str]) -> dict:
    """The digests of ``pairs`` with the roto of ``checkout`` first on the path."""
    code = "import json,sys,roto; from rollout_digest import rollout_keys as r; "
    code += "print(roto.__file__); print(json.dumps({p: r(*p.split(':')) for p in sys.argv[1:]}))"
    here = os.path.dirname(os.path.abspath(__file__))
    env = {**os.environ, "PYTHONPATH": f"{checkout}{os.pathsep}{here}"}
    lines = subprocess.run(
        [sys.executable, "-c", code, *pairs], env=env, cwd=here, capture_output=True, text=True, check=True
    ).stdout.splitlines()
    if not lines[0].startswith(os.path.abspath(checkout)):
        raise SystemExit(f"roto came from {lines[0]}, not {checkout}")
    return json.loads(lines[-1])


if __name__ == "__main__":
    old, new, *pairs = sys.argv[1:]
    before, after = run_at(old, pairs), run_at(new, pairs)
    for pair in pairs:
        a, b = before[pair], after[pair]
        same = sorted(k for k in a.keys() & b.keys() if a[k][0] == b[k][0])
        differ = sorted(k for k in a.keys() & b.keys() if a[k][0] != b[k][0])
        only = {k: (a.get(k) or b.get(k))[1] for k in sorted(a.keys() ^ b.keys())}
        side = {k: ("old" if k in a else "new") for k in only}
        print(f"{pair}: {len(same)} keys identical; differ: {differ or 'none'}")
        for key, largest in only.items():
            print(f"  only at {side[key]}: {key} (largest magnitude {largest:g})")

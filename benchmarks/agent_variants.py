"""Train agent variants on one (task, robot, obs mode) over seeds, evaluate them, tabulate and plot.

    python benchmarks/agent_variants.py bounce --steps 5000000 --seeds 0 1 --out benchmarks/results

Every (variant, seed) is an ordinary run directory under ``--runs`` (``<runs>/<task>/<variant>/seed<k>``).
The script is resumable: rerun the same command and finished runs (those with a summary, below,
even from another sitting) are skipped, interrupted ones continue from their latest checkpoint,
and missing final evaluations are done. Each run's final
policy (``latest.pt``) and best policy (``best.pt``) are evaluated over ``--episodes`` fresh
episodes, as ``roto eval`` does. The results go to ``<out>/variants_<task>_<robot>_<obs>_<steps>k.json``
(every figure, with the commits) and a curve of the evaluation metric per variant (mean over seeds).

Each finished run leaves a small summary, ``<variant>_seed<k>.json`` in the folder of that name
beside the table (its evaluation curve, final evaluations, costs and commit), meant to be committed; the table and
plot are made from every summary in that folder, so seeds trained in different sittings (whose run
directories are gone) still combine.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import statistics
import subprocess
import time

import torch

from roto.envs.config import EnvConfig
from roto.eval.evaluate import evaluate
from roto.eval.plots import plot_variants, read_scalars
from roto.rl.config import load_agent_config
from roto.rl.evaluation import read_evaluations
from roto.rl.overrides import apply_env_overrides, split_overrides
from roto.rl.runner import CHECKPOINT_DIR, Trainer, TrainSettings, load_policy

FD = "weight: 0.0021, lr: 1.5e-5, seq_length: 8, max_sequences: 292"
"""roto's tuned Bounce forward-dynamics coefficients (docs/spec.md §7a), used by both FD variants,
with at most 292 = 16 x 128 / 7 sequences per update, about one pass over the rollout's observations."""

VARIANTS = {
    "bounce": {
        "config": "bounce_cpu",
        "base": ["ppo.entropy_coef=0.004"],
        "ppo": [],
        "forward_dynamics": [f"ssl.forward_dynamics={{{FD}}}"],
        "forward_dynamics_memory": [f"ssl.forward_dynamics_memory={{{FD}}}"],
        "privileged_critic": ["network.critic=[tactile, proprio, privileged]"],
        "force_touch": ["env.touch=force"],
    },
    "baoding": {
        "config": "baoding",
        "base": [],
        "ppo": [],
        "forward_dynamics_memory": ["ssl.forward_dynamics_memory={weight: 0.025, lr: 2.5e-4, seq_length: 2}"],
        "force_touch": ["env.touch=force"],
    },
}
"""Per task: the base agent config (a packaged name), overrides every variant shares ("base": for
Bounce a quarter of roto's entropy bonus, which keeps the action noise from drifting up within the
budget, docs/results.md) and each variant's own overrides on top; ``env.<key>=value`` ones change
the env (``force_touch``: PPO on force touch instead of binary touch)."""

METRIC = {"bounce": "bounces", "baoding": "rotations"}


def finished(run_dir: pathlib.Path, steps: int) -> bool:
    """Whether the run's last evaluation was at the end of a ``steps`` budget."""
    records = read_evaluations(run_dir)
    return bool(records) and records[-1]["env_steps"] >= steps


def train_one(task: str, variant: str, seed: int, args: argparse.Namespace) -> pathlib.Path:
    """Train (or resume, or skip) one run; its run directory."""
    run_dir = pathlib.Path(args.runs) / task / variant / f"seed{seed}"
    if (run_dir / CHECKPOINT_DIR / "latest.pt").is_file():
        trainer = Trainer.resume(run_dir, total_steps=args.steps)
    else:
        env_changes, overrides = split_overrides([*VARIANTS[task]["base"], *VARIANTS[task][variant]])
        env = EnvConfig(task=task, robot=args.robot, obs_mode=args.obs, num_envs=args.num_envs, seed=seed,
                        threads=args.threads)  # fmt: skip
        env = apply_env_overrides(env, env_changes)
        agent = load_agent_config(task, VARIANTS[task]["config"], overrides)
        trainer = Trainer(TrainSettings(env=env, total_steps=args.steps), agent, run_dir)
    if trainer.update < trainer.total_updates:
        print(f"{task}/{variant}/seed{seed}: training from update {trainer.update}", flush=True)
        trainer.train(progress=False)
    trainer.env.close()
    trainer.evaluator.env.close()
    return run_dir


def final_evaluations(run_dir: pathlib.Path, episodes: int) -> dict[str, dict]:
    """``roto eval`` of latest.pt and best.pt over ``episodes`` episodes (cached next to them)."""
    out = {}
    for name in ("latest", "best"):
        cache = run_dir / CHECKPOINT_DIR / f"{name}.eval{episodes}.json"
        if not cache.is_file():
            model, settings, _ = load_policy(run_dir / CHECKPOINT_DIR / f"{name}.pt")
            result = evaluate(model, settings, episodes=episodes)
            cache.write_text(json.dumps(result))
        result = json.loads(cache.read_text())
        out[name] = {k: v for k, v in result.items() if k != "per_episode"}
    return out


def median_costs(run_dir: pathlib.Path) -> dict[str, float]:
    """Median seconds per update of simulation, inference and the update, and env steps/s, over the run."""
    series = read_scalars(run_dir)
    tags = ("perf/simulation_s", "perf/inference_s", "perf/update_s", "perf/steps_per_s")
    return {tag.removeprefix("perf/"): statistics.median(series[tag][1]) for tag in tags}


def summarize_run(run_dir: pathlib.Path, episodes: int) -> dict:
    """What the results table needs of one run."""
    records = read_evaluations(run_dir)
    best = max(records, key=lambda r: r["return_mean"])
    return {
        "run_dir": str(run_dir),
        "median_per_update": median_costs(run_dir),
        "train_wall_s": records[-1]["train_wall_s"],
        "env_steps": records[-1]["env_steps"],
        "best_update": best["update"],
        "evaluations": [{k: v for k, v in r.items() if k != "per_episode"} for r in records],
        "eval": final_evaluations(run_dir, episodes),
    }


def report(task: str, folder: pathlib.Path, meta: dict) -> None:
    """Tabulate and plot every run summary in ``folder`` (whichever sitting wrote it)."""
    results: dict[str, list[dict]] = {}
    for path in sorted(folder.glob("*_seed*.json")):
        summary = json.loads(path.read_text())
        results.setdefault(summary["variant"], []).append(summary)
    stem = folder.name
    commits = sorted({r["commit"] for runs in results.values() for r in runs})
    overrides = {variant: VARIANTS[task][variant] for variant in results}
    table = {"meta": {**meta, "overrides": overrides, "commits": commits}, "results": results}
    (folder.parent / f"{stem}.json").write_text(json.dumps(table, indent=1))
    curves = {variant: [r["evaluations"] for r in runs] for variant, runs in results.items()}
    title = f"{stem}\ncommits {', '.join(commits)}"  # two lines: a long commit list fits
    plot_variants(curves, METRIC[task], folder.parent / f"{stem}.png", title=title)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("task", choices=sorted(VARIANTS))
    parser.add_argument("--variants", nargs="*", default=None, help="default: every variant of the task")
    parser.add_argument("--robot", default="shadow")
    parser.add_argument("--obs", default="blind")
    parser.add_argument("--steps", type=int, default=5_000_000)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--num_envs", type=int, default=128)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--torch_threads", type=int, default=2)
    parser.add_argument("--episodes", type=int, default=100)
    parser.add_argument("--runs", default="runs/variants")
    parser.add_argument("--out", default="benchmarks/results")
    parser.add_argument("--report_only", action="store_true", help="train nothing; summarise finished runs, report")
    parser.add_argument(
        "--code_commit", default=None, help="commit the runs were trained at (default: HEAD when this script starts)"
    )
    args = parser.parse_args()
    torch.set_num_threads(args.torch_threads)
    variants = args.variants or [v for v in VARIANTS[args.task] if v not in ("config", "base")]
    start = time.time()
    # the code this process trains with: read now, since the checkout may move on while it runs
    commit = (
        args.code_commit
        or subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    )
    folder = pathlib.Path(args.out) / f"variants_{args.task}_{args.robot}_{args.obs}_{args.steps // 1000}k"
    folder.mkdir(parents=True, exist_ok=True)
    for seed in args.seeds:  # seed-major: every variant gets its first seed before any gets a second
        for variant in variants:
            run_dir = pathlib.Path(args.runs) / args.task / variant / f"seed{seed}"
            if (folder / f"{variant}_seed{seed}.json").is_file():  # finished, maybe in another sitting
                print(f"{args.task}/{variant}/seed{seed}: summary exists, skipped", flush=True)
                continue
            if not args.report_only:
                train_one(args.task, variant, seed, args)
            elif not finished(run_dir, args.steps):
                print(f"{run_dir}: not finished, left out of the report", flush=True)
                continue
            summary = {"variant": variant, "seed": seed, "commit": commit, **summarize_run(run_dir, args.episodes)}
            (folder / f"{variant}_seed{seed}.json").write_text(json.dumps(summary, indent=1))
    meta = {"steps": args.steps, "num_envs": args.num_envs, "threads": args.threads, "episodes": args.episodes,
            "base_config": VARIANTS[args.task]["config"], "base_overrides": VARIANTS[args.task]["base"]}  # fmt: skip
    report(args.task, folder, meta)
    print(f"done in {time.time() - start:.0f} s: {folder}.json", flush=True)


if __name__ == "__main__":
    main()

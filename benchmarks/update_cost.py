"""What one PPO update costs at a training setting's shapes, eager against replayed from a CUDA graph.

    python benchmarks/update_cost.py --device cuda --num_envs 8192 [--agent_cfg bounce] [--updates 6]

Builds the learner of blind (task, robot) with the packaged agent config, fills its rollout buffer
with made-up observations and rewards (no simulation: this isolates the update), and times
``update()`` per variant, one JSON line each: the median seconds per update over the updates after
the first (the first compiles, captures and warms up) and the samples per second that makes.
A variant is a set of the update's speed settings (``--variants``, default: all but
``eager_fused`` and ``eager_bf16`` on a CUDA device; ``eager``, ``eager_fused`` and ``eager_bf16``
on the CPU): ``cuda_graph``
replays each minibatch step from a CUDA graph (``ppo.cuda_graph=true``), ``fused`` steps Adam
with the fused implementation
(``ppo.fused_adam=true``), ``tf32`` lets the update's matrix products use TF32
(``ppo.tf32_update=true``), ``bf16`` runs the update's forward and backward passes under bfloat16
autocast (``ppo.bf16_update=true``), ``compiled`` compiles the forward pass and loss terms with torch.compile
(``ppo.compile_update=true``); ``eager`` is none of them. ``--profile`` adds, on a GPU, the kernels'
device time per minibatch step from one more update under torch.profiler.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import torch

from roto.envs.config import EnvConfig
from roto.envs.roto_env import RotoEnv
from roto.rl.build import build_learner, build_model, extra_groups, stacked_sizes
from roto.rl.config_files import load_agent_config
from roto.rl.ppo import PPO


def fill(alg: PPO, sizes: dict[str, int], generator: torch.Generator) -> None:
    """One rollout of standard-normal observations and rewards, 5 % episode ends, then the returns."""
    buffer, device = alg.storage, alg.storage.values.device

    def obs() -> dict[str, torch.Tensor]:
        return {g: torch.randn(buffer.num_envs, d, device=device, generator=generator) for g, d in sizes.items()}

    for _ in range(buffer.steps):
        alg.act(obs())
        reward = torch.randn(buffer.num_envs, device=device, generator=generator)
        done = torch.rand(buffer.num_envs, device=device, generator=generator) < 0.05
        alg.process_step(reward, done, torch.zeros_like(done), {})
    alg.compute_returns(obs())


GRAPH, FUSED, TF32, BF16 = "ppo.cuda_graph=true", "ppo.fused_adam=true", "ppo.tf32_update=true", "ppo.bf16_update=true"
COMPILED = "ppo.compile_update=true"
VARIANTS = {
    "eager": [],
    "eager_fused": [FUSED],
    "eager_tf32": [TF32],
    "eager_bf16": [BF16],
    "cuda_graph": [GRAPH],
    "cuda_graph_tf32": [GRAPH, TF32],
    "cuda_graph_fused": [GRAPH, FUSED],
    "cuda_graph_fused_tf32": [GRAPH, FUSED, TF32],
    "eager_fused_tf32_compiled": [FUSED, TF32, COMPILED],
    "cuda_graph_fused_tf32_compiled": [GRAPH, FUSED, TF32, COMPILED],
}
"""Variant name -> the agent-config overrides it times."""
CPU_VARIANTS = ("eager", "eager_fused", "eager_bf16")  # compiled ones only when named: their first update compiles
GPU_VARIANTS = tuple(name for name in VARIANTS if name not in ("eager_fused", "eager_bf16"))


def measure(args: argparse.Namespace, variant: str) -> dict[str, object]:
    """Median seconds per update of one variant."""
    device = torch.device(args.device)
    agent = load_agent_config(args.task, args.agent_cfg, VARIANTS[variant])
    groups = extra_groups(agent, "blind")  # a privileged critic's groups come from the env too
    probe = RotoEnv(EnvConfig(task=args.task, robot=args.robot, num_envs=1, extra_groups=groups))
    sizes, num_actions = stacked_sizes(probe), probe.num_actions
    torch.manual_seed(0)
    model = build_model(sizes, num_actions, agent, "blind").to(device)
    alg = build_learner(model, sizes, num_actions, args.num_envs, agent, seed=0, touch="binary")
    generator = torch.Generator(device=device).manual_seed(0)
    seconds = []
    for _ in range(args.updates):
        fill(alg, sizes, generator)
        if device.type == "cuda":
            torch.cuda.synchronize()
        start = time.perf_counter()
        alg.update()  # ends with host reads of its metrics, so the device is done when it returns
        seconds.append(time.perf_counter() - start)
    median = statistics.median(seconds[1:])
    kernels = device_time(alg, sizes, generator) if args.profile and device.type == "cuda" else {}
    samples = agent.ppo.rollouts * args.num_envs * agent.ppo.epochs
    return {
        "variant": variant,
        "task": args.task,
        "robot": args.robot,
        "agent_cfg": args.agent_cfg or args.task,
        "num_envs": args.num_envs,
        "device": torch.cuda.get_device_name(device) if device.type == "cuda" else "cpu",
        "minibatch_steps": agent.ppo.epochs * agent.ppo.minibatches,
        "update_s": round(median, 5),
        "first_update_s": round(seconds[0], 3),
        "samples_per_s": round(samples / median),
        **kernels,
    }


def device_time(alg: PPO, sizes: dict[str, int], generator: torch.Generator) -> dict[str, object]:
    """One more update under torch.profiler: the GPU's busy time (the sum of its kernels' durations),
    the number of kernels, and the five kernels that took longest in all, per minibatch step."""
    from torch.profiler import ProfilerActivity, profile

    fill(alg, sizes, generator)
    torch.cuda.synchronize()
    with profile(activities=[ProfilerActivity.CUDA]) as prof:
        alg.update()
        torch.cuda.synchronize()
    steps = alg.config.epochs * alg.config.minibatches
    events = [e for e in prof.key_averages() if e.device_time_total > 0]
    top = sorted(events, key=lambda e: e.device_time_total, reverse=True)[:5]
    return {
        "kernel_ms_per_step": round(sum(e.device_time_total for e in events) / 1e3 / steps, 4),
        "kernels_per_step": round(sum(e.count for e in events) / steps, 1),
        "top_kernels_ms_per_step": {e.key[:80]: round(e.device_time_total / 1e3 / steps, 4) for e in top},
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--task", default="bounce")
    parser.add_argument("--robot", default="shadow")
    parser.add_argument("--agent_cfg", default=None, help="packaged agent config (default: the task's)")
    parser.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    parser.add_argument("--num_envs", type=int, default=8192)
    parser.add_argument("--updates", type=int, default=6, help="timed updates per variant (the first is dropped)")
    parser.add_argument("--variants", nargs="+", default=None, choices=list(VARIANTS), help="default: see above")
    parser.add_argument("--profile", action="store_true", help="on a GPU, add each variant's kernel time per step")
    args = parser.parse_args()
    if args.updates < 2:
        parser.error(f"--updates must be >= 2 (the first one is not counted), got {args.updates}")
    for variant in args.variants or (CPU_VARIANTS if args.device == "cpu" else GPU_VARIANTS):
        print(json.dumps(measure(args, variant)), flush=True)


if __name__ == "__main__":
    main()

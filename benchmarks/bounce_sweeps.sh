#!/usr/bin/env bash
# A blind Bounce sweep per hand other than the Shadow (whose sweep made bounce_cpu_quickstart), each
# started from the Shadow's configuration (enqueued as its first trial), at the CPU Olympiad's
# budget of 5 M env steps, then exported as the hand's packaged config roto/configs/bounce_cpu_<hand>.yaml
# (a diff from bounce_cpu_quickstart). Two one-thread workers; about 16 trials x 40 minutes / 2 per
# hand, fewer when pruned. Rerunning continues where it stopped: a finished study has its trials
# (and interrupted trials are retried from their checkpoints, --reclaim-now: no other worker runs).
#     bash benchmarks/bounce_sweeps.sh [hand ...]      (default: shadow_lite allegro orca)
set -euo pipefail
hands=("$@")
[[ ${#hands[@]} -gt 0 ]] || hands=(shadow_lite allegro orca)
mkdir -p benchmarks/results/sweeps
for robot in "${hands[@]}"; do
    study="bounce_cpu_$robot"
    roto sweep --study "$study" --task bounce --robot "$robot" --obs blind \
        --agent_cfg bounce_cpu_quickstart --space cpu_quickstart --steps 5000000 --trials 16 --startup 4 \
        --enqueue_base --num_envs 128 --threads 1 --torch_threads 1 --workers 2 --reclaim-now
    roto sweep show --study "$study" > "benchmarks/results/sweeps/$study.md"
    roto sweep export --study "$study" --out "roto/configs/bounce_cpu_$robot.yaml"
done

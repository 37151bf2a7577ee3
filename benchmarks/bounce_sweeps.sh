#!/usr/bin/env bash
# A blind Bounce sweep per hand other than the Shadow (whose sweep made bounce_cpu_quickstart), each
# started from the Shadow's configuration (enqueued as its first trial), at the CPU Olympiad's
# budget of 5 M env steps, then exported as a candidate config, benchmarks/results/sweeps/<study>.yaml
# (a diff from bounce_cpu_quickstart). A candidate becomes the hand's recipe (roto/configs/, named in
# the hand's record, PairRecord.recipe) only after the Olympiad's seeds confirm it (docs/sweeps.md). Two
# one-thread workers; about 16 trials x 40 minutes / 2 per hand, fewer when pruned. Each study's
# journal lives in benchmarks/results/sweeps/<study>.journal.log (commit it after a sitting), so
# rerunning continues where it stopped, on this machine or on a new clone: finished trials stay
# finished, and interrupted ones are retried (--reclaim-now: no other worker runs) from their
# checkpoints where runs/ still has them, from their start where not.
#     bash benchmarks/bounce_sweeps.sh [hand ...]      (default: shadow_lite allegro orca)
#     WORKERS=1 bash benchmarks/bounce_sweeps.sh shadow_lite   (one worker, beside another job)
set -euo pipefail
hands=("$@")
[[ ${#hands[@]} -gt 0 ]] || hands=(shadow_lite allegro orca)
mkdir -p benchmarks/results/sweeps
for robot in "${hands[@]}"; do
    study="bounce_cpu_$robot"
    space=cpu_quickstart  # ORCA's random actions already bounce the ball: its space also searches the initial noise
    [[ $robot == orca ]] && space=cpu_quickstart_noise
    journal="benchmarks/results/sweeps/$study.journal.log"
    roto sweep --study "$study" --task bounce --robot "$robot" --obs blind \
        --agent_cfg bounce_cpu_quickstart --space "$space" --steps 5000000 --trials 16 --startup 4 \
        --enqueue_base --num_envs 128 --threads 1 --torch_threads 1 --workers "${WORKERS:-2}" --reclaim-now \
        --storage "$journal"
    roto sweep show --study "$study" --storage "$journal" > "benchmarks/results/sweeps/$study.md"
    roto sweep export --study "$study" --storage "$journal" --out "benchmarks/results/sweeps/$study.yaml"
done

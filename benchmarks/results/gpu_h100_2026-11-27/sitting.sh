#!/usr/bin/env bash
# The GPU sitting of 2026-11-27, its last call: install the packages, compile and bench blind Shadow
# Bounce and Baoding at 8192 envs, send the kernel cache back (so a later sitting compiles nothing),
# then train the Shadow's CPU Baoding recipe (baoding_cpu_shadow) at 8192 envs with the graphed TF32
# update for the time left (issue: the recipe at 8192 envs). The three calls before it copied
# .whl1 ... .whl3 (the parts of benchmarks/gpu_wheels.sh) into /tmp/whl.
#   usage (on the GPU machine, in the repo root): BUDGET_S=500 bash benchmarks/results/gpu_2026-11-27/sitting.sh
# Everything lands in $OUT: sitting.tgz (the suite's files, the run without full checkpoints),
# kernels.tar.xz.part-NN (the kernel cache), sitting.log.
set -u
t0=$(date +%s)
deadline=$(( t0 + ${BUDGET_S:?usage: BUDGET_S=seconds bash sitting.sh} ))
out=/tmp/sitting
mkdir -p "$out"
log() { echo "$* ($(( $(date +%s) - t0 )) s)" | tee -a "$out/sitting.log"; }
bash benchmarks/gpu_machine.sh install .whl4 || exit 1
export PYTHONPATH=/tmp/site:$PWD ROTO_WARP_CACHE=/tmp/wc PYTHONUNBUFFERED=1
log "install done"
PAIRS="bounce:shadow baoding:shadow" SCALING="" PYTEST_FILES="" UPDATE_AGENTS="" bash benchmarks/gpu_suite.sh "$out/bench" 0 8192
log "bench done"
tar -C /tmp -cf - wc | xz -T0 -6 | split -b 15M -d -a 2 - "$OUT/kernels.tar.xz.part-"
log "kernel cache packed: $(du -sm /tmp/wc | cut -f1) MiB"
every=(run.eval_every=20 run.checkpoint_every=40)
# training stops 25 s before the deadline (the suite keeps 60 s for the policies; they take about 6)
DEADLINE=$(( deadline + 35 )) PAIRS="" SCALING="" PYTEST_FILES="" UPDATE_AGENTS="" TRAIN_TASK=baoding TRAIN_ROBOT=shadow \
  bash benchmarks/gpu_suite.sh "$out/recipe" 600 8192 --agent_cfg baoding_cpu_shadow ppo.cuda_graph=true \
  ppo.tf32_update=true "${every[@]}"
log "recipe done"
# if the graphed recipe failed early, the same recipe with the eager update for the time left
if ! grep -qE "^train: exit (0|124) " "$out/recipe/suite.log" && [ $(( deadline - $(date +%s) )) -gt 120 ]; then
  DEADLINE=$(( deadline + 35 )) PAIRS="" SCALING="" PYTEST_FILES="" UPDATE_AGENTS="" TRAIN_TASK=baoding \
    TRAIN_ROBOT=shadow bash benchmarks/gpu_suite.sh "$out/recipe_eager" 600 8192 --agent_cfg baoding_cpu_shadow \
    ppo.tf32_update=true "${every[@]}"
  log "recipe (eager) done"
fi
tar -C /tmp --exclude='*tfevents*' --exclude='checkpoints' -czf "$OUT/sitting.tgz" sitting
cp "$out/sitting.log" "$OUT/"
ls -l "$OUT"
